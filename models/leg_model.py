"""The leg model: a calibrated probability that a scan segment is a person's leg, from its shape.

A gradient-boosted ensemble of small regression trees over the metric features of
:mod:`people_tracker.detection.leg_features`, fitted by ``people-tracker train-legs`` (scikit-learn,
the ``[train]`` extra) and stored as plain arrays in a ``.npz`` file; here it is evaluated
in numpy alone, every tree at once, one gather per tree level. The ensemble's log-odds go
through an isotonic calibration map fitted on held-out folds, so the score is a
probability: of the candidates scored about 0.7, about 70 % are legs (for the mix of
people and empty rooms it was fitted on).

The shipped model (``leg_model.npz`` beside this file) was fitted with
``people-tracker train-legs`` on Leigh et al.'s labelled legs (``positive_{1,2,3}_extracted``,
also pasted into the empty rooms), the empty rooms of ``negative_2.bag`` (``/left_scan``,
``/right_scan``) and 600 scans of simulated furnished rooms with people, each scan also at
every 2nd and 3rd beam, so the model sees other rooms, other legs and coarser lasers too;
its calibration map is fitted on the recorded examples alone.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from people_tracker.models import compiled
from people_tracker.models.compiled import njit

SHIPPED = "leg_model.npz"


@dataclass(frozen=True, eq=False)
class LegModel:
    """A tree ensemble and its calibration.

    Attributes
    ----------
    feature_names : tuple of str
        The features each column of the input holds, in order.
    feature, threshold, left, right, value : ndarray, shape (n_trees, n_nodes)
        Each tree's nodes: split feature and threshold (go left when ``x <= threshold``),
        children, and the leaf's contribution to the log-odds (learning rate included).
        Leaves are their own children, so a walk of ``depth`` steps ends on one.
    depth : int
    init : float
        Log-odds before the first tree.
    calib_raw, calib_p : ndarray, shape (m,)
        The calibration map: log-odds (increasing) to probability, linear between.
    meta : dict
        What the model was fitted on.
    """

    feature_names: tuple[str, ...]
    feature: np.ndarray
    threshold: np.ndarray
    left: np.ndarray
    right: np.ndarray
    value: np.ndarray
    depth: int
    init: float
    calib_raw: np.ndarray
    calib_p: np.ndarray
    meta: dict

    def __post_init__(self) -> None:
        object.__setattr__(self, "_heap", _complete_trees(self))

    def log_odds(self, x: np.ndarray) -> np.ndarray:
        """The ensemble's raw score of each row of ``x`` (shape (k, n_features)), shape (k,)."""
        x = np.asarray(x, dtype=np.float64)
        if len(x) == 0:
            return np.zeros(0)
        feature, threshold, leaves = self._heap  # complete trees in heap order: children 2i+1, 2i+2
        if compiled.on:  # the walk compiled; the sum stays numpy's (its order of additions)
            return self.init + _leaf_values_kernel(x, feature, threshold, leaves, self.depth).sum(axis=1)
        n_trees = len(feature)
        base = (np.arange(n_trees) * feature.shape[1])[None, :]
        rows = (np.arange(len(x)) * x.shape[1])[:, None]
        flat_f, flat_t, flat_x = feature.ravel(), threshold.ravel(), x.ravel()
        node = np.zeros((len(x), n_trees), dtype=np.int64)
        for _ in range(self.depth):
            at = base + node
            # go right when x > threshold: child 2i + 2, else 2i + 1
            node = 2 * node + 1 + (flat_x[rows + flat_f[at]] > flat_t[at])
        leaf = node - (feature.shape[1])  # leaves follow the inner nodes
        return self.init + leaves.ravel()[(np.arange(n_trees) * leaves.shape[1])[None, :] + leaf].sum(axis=1)

    @property
    def base_rate(self) -> float:
        """Share of legs among the candidates the model was fitted on: the probability it
        gives when the shape says nothing (to turn its scores into likelihood ratios)."""
        if "base_rate" in self.meta:
            return float(self.meta["base_rate"])
        pos, neg = self.meta.get("positives"), self.meta.get("negatives")
        return float(pos) / (pos + neg) if pos and neg else 0.5

    def probability(self, x: np.ndarray) -> np.ndarray:
        """Calibrated probability that each row of ``x`` is a leg, shape (k,)."""
        return np.interp(self.log_odds(x), self.calib_raw, self.calib_p)

    def save(self, target) -> None:
        """Write the model to ``target``: a path (``.npz``) or a binary file object."""
        if isinstance(target, (str, Path)):
            with open(target, "wb") as fh:
                return self.save(fh)
        np.savez_compressed(target, feature_names=np.array(self.feature_names), feature=self.feature,
                                threshold=self.threshold, left=self.left, right=self.right, value=self.value,
                                depth=self.depth, init=self.init, calib_raw=self.calib_raw, calib_p=self.calib_p,
                                meta=json.dumps(self.meta))
        return None


def _complete_trees(model: LegModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every tree as a complete binary tree of ``depth`` levels in heap order: split
    features and thresholds of the ``2**depth - 1`` inner nodes, and the ``2**depth`` leaf
    values. A leaf above the last level becomes nodes that always go left (threshold
    +inf) down to copies of its value."""
    d = model.depth
    n_inner = 2 ** d - 1
    feature = np.zeros((len(model.feature), n_inner), dtype=np.int64)
    threshold = np.full((len(model.feature), n_inner), np.inf)
    leaves = np.zeros((len(model.feature), 2 ** d))
    for t in range(len(model.feature)):
        stack = [(0, 0, 0)]  # (node in the model's tree, place in the heap, level)
        while stack:
            node, h, level = stack.pop()
            is_leaf = model.left[t, node] == node
            if level == d:
                if not is_leaf:
                    raise ValueError(f"tree {t} is deeper than the model's depth {d}")
                leaves[t, h - n_inner] = model.value[t, node]
                continue
            if is_leaf:
                stack += [(node, 2 * h + 1, level + 1), (node, 2 * h + 2, level + 1)]
            else:
                feature[t, h] = model.feature[t, node]
                threshold[t, h] = model.threshold[t, node]
                stack += [(model.left[t, node], 2 * h + 1, level + 1), (model.right[t, node], 2 * h + 2, level + 1)]
    return feature, threshold, leaves


class LegModelError(ValueError):
    """A model file that cannot be used."""


def load_leg_model(path: str | Path | None = None) -> LegModel:
    """The model at ``path``, or the shipped one (``None`` or ``"default"``).

    Raises :class:`LegModelError` (a ``ValueError``) naming the problem for a missing or
    malformed file.
    """
    if path is None or str(path) == "default":
        source = resources.files(__package__).joinpath(SHIPPED)
        where = "the shipped leg model"
    else:
        source = Path(path)
        where = f"leg model '{path}'"
        if not source.is_file():
            raise LegModelError(f"{where} does not exist")
    try:
        with source.open("rb") as fh, np.load(fh, allow_pickle=False) as z:
            model = LegModel(tuple(str(s) for s in z["feature_names"]), z["feature"].astype(np.int64),
                             z["threshold"].astype(np.float64), z["left"].astype(np.int64),
                             z["right"].astype(np.int64), z["value"].astype(np.float64), int(z["depth"]),
                             float(z["init"]), z["calib_raw"].astype(np.float64), z["calib_p"].astype(np.float64),
                             json.loads(str(z["meta"])))
    except (OSError, KeyError, ValueError, IndexError) as exc:
        raise LegModelError(f"{where} cannot be read: {' '.join(str(exc).split())[:150]}") from None
    shapes = {a.shape for a in (model.feature, model.threshold, model.left, model.right, model.value)}
    # (a tree deeper than its stated depth fails when the model is built: ValueError above)
    if len(shapes) != 1 or model.feature.ndim != 2 or len(model.calib_raw) != len(model.calib_p) \
            or len(model.calib_raw) < 2 or model.feature.max(initial=0) >= len(model.feature_names):
        raise LegModelError(f"{where} is malformed")
    return model


def _leaf_values_loop(x, feature, threshold, leaves, depth):
    """Each row of ``x`` walked down every complete tree (:meth:`LegModel.log_odds`' numpy
    walk is the reference): the leaf values it ends on, shape (len(x), n_trees)."""
    n_trees, n_inner = feature.shape
    out = np.empty((len(x), n_trees))
    for i in range(len(x)):
        for t in range(n_trees):
            node = 0
            for _ in range(depth):
                node = 2 * node + (2 if x[i, feature[t, node]] > threshold[t, node] else 1)
            out[i, t] = leaves[t, node - n_inner]
    return out


_leaf_values_kernel = njit(_leaf_values_loop)
