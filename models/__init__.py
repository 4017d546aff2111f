"""Physical and probabilistic models shared by every layer.

Imports nothing from ``detection`` or ``tracker``.
"""

from models.pose import Pose2D
from models.scan import Scan

__all__ = ["Pose2D", "Scan"]
