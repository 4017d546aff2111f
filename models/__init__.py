"""Physical and probabilistic models shared by every layer.

Imports nothing from ``detection`` or ``tracker``.
"""

from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import Scan

__all__ = ["Pose2D", "Scan"]
