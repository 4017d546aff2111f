"""Compiled kernels for the hot path (numba, the ``[fast]`` extra), and the switch between
them and the numpy code they stand in for.

Most of a scan's time goes to a few hundred small numpy operations, each a few
microseconds of call overhead around a few hundred numbers of work. Where one stage is a
long chain of such operations, a kernel here does the same arithmetic in one compiled loop.
Every kernel has its numpy twin, which stays the reference: the kernel runs only when numba
is installed (``pip install "people-tracker[fast]"``) and ``PEOPLE_TRACKER_COMPILED`` is not
``0``; ``tests/detection/test_compiled.py`` checks that the two give the same answers on real
and simulated scans. Kernels are compiled on first use and cached on disk (numba's
``cache=True``), so only the first run on a machine pays the compilation. The cache lives in
the user's cache folder (:func:`cache_dir`: ``$XDG_CACHE_HOME/people-tracker/numba`` or
``~/.cache/people-tracker/numba`` on Linux), or in ``NUMBA_CACHE_DIR`` when that is set, never
beside the installed modules: files written into ``site-packages/people_tracker`` outlive
``pip uninstall``, and the folder they leave makes ``people_tracker`` a namespace package
over a later editable install.

The arithmetic follows the numpy code's order (the same expressions; a segment's sum in
the order ``np.add.reduceat`` adds, :func:`reduceat_sum`), and numba does not fuse or
reorder floating-point operations unless asked to (``fastmath`` is off), so the results
agree to the last bit on every scan the test has seen. One exception: an object's box
sides (:func:`people_tracker.detection.objects.describe_all`), which shapely takes from
corners GEOS intersects in double-double precision, agree to 1e-12 m. The kernels' bearings
come from the C library's atan2; numpy's arctan2 rounds differently on processors with
AVX-512, so the numpy twins take :data:`arctan2`, which is the C library's there. This module sits in ``models``,
beside :func:`people_tracker.models.scan.beam_index` whose one-bearing twin it holds, so
that every layer can use it (the leg model too).
"""

from __future__ import annotations

import math
import os
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np


def _load():
    if os.environ.get("PEOPLE_TRACKER_COMPILED", "1").strip() in ("0", "false", "no", "off"):
        return None
    try:
        import numba
    except ImportError:  # the [fast] extra is not installed: the numpy path runs
        return None
    return numba


_numba = _load()
ENABLED = _numba is not None  # installed and not switched off by the environment
on = ENABLED  # read by every caller at every call: numpy_only() turns it off for a while


@contextmanager
def numpy_only():
    """Run the numpy code instead of the kernels inside this block (the agreement tests, a
    benchmark's before and after)."""
    global on
    saved, on = on, False
    try:
        yield
    finally:
        on = saved


def numba_version() -> str | None:
    """The numba that compiles the kernels, None when they are off."""
    return _numba.__version__ if _numba is not None else None


_C_ATAN2 = np.frompyfunc(math.atan2, 2, 1)  # the C library's atan2 (CPython's math.atan2), per element


def _c_arctan2(y, x):
    """``np.arctan2(y, x)`` rounded as the C library rounds it, one element at a time
    (radians, float64)."""
    return np.asarray(_C_ATAN2(y, x), dtype=np.float64)


def _numpy_arctan2_is_the_c_librarys() -> bool:
    """Whether numpy's arctan2 gives the C library's bits here. The kernels call the C
    library's atan2; numpy's loops for AVX-512 processors round about one result in
    sixteen differently (by an ulp), which a bearing on a beam's edge turns into another
    beam."""
    rng = np.random.default_rng(0)
    y, x = rng.normal(size=(2, 4096)) * 10.0 ** rng.uniform(-3, 2, size=(2, 4096))
    return bool(np.array_equal(np.arctan2(y, x), _c_arctan2(y, x)))


# np.arctan2 for the numpy twins of the kernels: numpy's own where it rounds as the C
# library does (as the kernels do), else the C library's, element by element (slower:
# about 0.1 ms for 768 bearings, and only without numba or with it switched off)
arctan2 = np.arctan2 if _numpy_arctan2_is_the_c_librarys() else _c_arctan2


def _numpy_trig_is_the_c_librarys() -> bool:
    """Whether numpy's cos and sin give the C library's bits here (the kernels call the C
    library's; numpy's own loops for some processors may round differently)."""
    x = np.random.default_rng(1).uniform(-7.0, 7.0, 4096)
    return bool(np.array_equal(np.cos(x), [math.cos(v) for v in x])
                and np.array_equal(np.sin(x), [math.sin(v) for v in x]))


# whether a kernel may compute what numpy's cos and sin would (else numpy does it); only
# the kernels ask, so it is checked only when they are there
trig_is_numpys = ENABLED and _numpy_trig_is_the_c_librarys()


def cache_dir() -> Path:
    """Where the compiled kernels are kept when ``NUMBA_CACHE_DIR`` is not set: the
    platform's per-user cache folder, ``people-tracker/numba`` inside it. Numba keeps one
    subfolder per source folder (a hash of its full path), so an installed and an editable
    copy never share a cache entry."""
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local"
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "people-tracker" / "numba"


def uncompiled() -> int:
    """How many kernels imported so far have no compiled copy on disk yet (no numba cache
    index): a run that calls them compiles them first, about half a minute on the first run
    on a machine. 0 without numba, and when numba keeps its cache where this cannot tell."""
    n = 0
    for kernel in KERNELS:
        try:
            n += not os.path.exists(kernel._cache._cache_file._index_path)
        except AttributeError:  # a numba whose cache is laid out otherwise: unknown
            return 0
    return n


KERNELS: list = []  # every kernel the pipeline calls (not the helpers they call), for the warm-up's test


def njit(fn, helper: bool = False):
    """``fn`` compiled (no Python objects, cached on disk) when numba is on; else None.
    ``helper``: only called from other kernels (compiled into them)."""
    if _numba is None:
        return None
    # numba picks the cache's folder when the function is decorated, from config.CACHE_DIR
    # (NUMBA_CACHE_DIR); set ours for this decoration only, so other numba users in the
    # process keep theirs. A folder that cannot be written falls through to numba's own
    # choices (beside the module if writable, else numba's per-user folder).
    config = _numba.config
    saved = config.CACHE_DIR
    if not saved:
        config.CACHE_DIR = str(cache_dir())
    try:
        kernel = _numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")(fn)
    finally:
        config.CACHE_DIR = saved
    if not helper:
        KERNELS.append(kernel)
    return kernel


# Helpers the kernels share: plain functions, compiled with them (None-safe: without
# numba they stay Python, and nothing calls them).

def _block(x, lo, n):
    """numpy's pairwise summation of ``x[lo:lo+n]`` for n <= 128: one run, or eight
    interleaved partial sums added as a tree, then the rest one by one."""
    if n < 8:
        res = -0.0  # as numpy: a sum of negative zeros stays negative
        for i in range(lo, lo + n):
            res += x[i]
        return res
    r0, r1, r2, r3 = x[lo], x[lo + 1], x[lo + 2], x[lo + 3]
    r4, r5, r6, r7 = x[lo + 4], x[lo + 5], x[lo + 6], x[lo + 7]
    i = 8
    while i < n - n % 8:
        r0 += x[lo + i]
        r1 += x[lo + i + 1]
        r2 += x[lo + i + 2]
        r3 += x[lo + i + 3]
        r4 += x[lo + i + 4]
        r5 += x[lo + i + 5]
        r6 += x[lo + i + 6]
        r7 += x[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += x[lo + i]
        i += 1
    return res


def _pairwise(x, lo, n):
    """numpy's pairwise summation of ``x[lo:lo+n]`` (the order ``np.add.reduceat`` adds a
    segment in), so the compiled sums equal numpy's to the last bit. Longer runs
    than 128 split in two (the first half a multiple of 8) and add the halves' sums: the
    recursion is unrolled on a stack here (numba's on-disk cache cannot hold a recursive
    function)."""
    if n <= 128:
        return _block(x, lo, n)
    s_lo = np.empty(64, np.int64)
    s_n = np.empty(64, np.int64)
    s_stage = np.zeros(64, np.int64)  # 0: left half next, 1: right half next, 2: both done
    s_left = np.zeros(64)
    top, ret = 0, 0.0
    s_lo[0], s_n[0] = lo, n
    while top >= 0:
        if s_n[top] <= 128:
            ret = _block(x, s_lo[top], s_n[top])
            top -= 1
            continue
        half = s_n[top] // 2
        half -= half % 8
        if s_stage[top] == 0:
            s_stage[top] = 1
            top += 1
            s_lo[top], s_n[top], s_stage[top] = s_lo[top - 1], half, 0
        elif s_stage[top] == 1:
            s_left[top], s_stage[top] = ret, 2
            top += 1
            s_lo[top], s_n[top], s_stage[top] = s_lo[top - 1] + half, s_n[top - 1] - half, 0
        else:
            ret = s_left[top] + ret
            top -= 1
    return ret


def reduceat_sum(x):
    """The sum ``np.add.reduceat`` gives for a non-empty 1-D segment ``x``: its first
    element, then the rest pairwise. (Not always ``np.add.reduce``'s: on a contiguous array
    longer than 128, numpy's reduce adds in another order.)"""
    return x[0] + _pairwise(x, 1, len(x) - 1)


def beam_of(bearing, angle_min, angle_increment, n_beams):
    """:func:`people_tracker.models.scan.beam_index` of one bearing, the same operations in the same order."""
    res = abs(angle_increment)
    centre = 0.5 * (n_beams - 1) * res
    offset = bearing - angle_min
    if angle_increment < 0:
        offset = -offset
    offset = np.mod(offset - centre + np.pi, 2.0 * np.pi) - np.pi + centre
    step = np.rint(offset / res)
    if n_beams * res >= 2.0 * np.pi - 0.5 * res:
        if np.isfinite(step) and step > -n_beams and step < 2 * n_beams:
            return np.mod(np.int64(step), n_beams)
        return -1
    if step >= 0 and step < n_beams:
        return np.int64(step)
    return -1


def bin_of(x, y, angle_min, angle_increment, n_beams):
    """:func:`people_tracker.detection.scan_lines.bin_to_beams` of one point (x, y), sensor
    frame, metres: the beam whose line of sight passes nearest it, -1 outside the view."""
    return beam_of(np.arctan2(y, x), angle_min, angle_increment, n_beams)


_block = njit(_block, helper=True) or _block
_pairwise = njit(_pairwise, helper=True) or _pairwise
reduceat_sum = njit(reduceat_sum, helper=True) or reduceat_sum
beam_of = njit(beam_of, helper=True) or beam_of
bin_of = njit(bin_of, helper=True) or bin_of
