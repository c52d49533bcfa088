"""hsr: watertight polygonal surface reconstruction of man-made scenes from point clouds.

The package re-exports every public function and class of the compiled module ``hsr._hsr`` unchanged
(``hsr.reconstruct``, ``hsr.read_points``, ``hsr.Error``, ...; see README "Python"), and holds the Dask
drivers of ``hsr batch``: ``python3 -m hsr.batch INPUT... -o DIR`` (``hsr.batch``) and of ``hsr city``:
``python3 -m hsr.city TILE... -o OUT.city.jsonl`` (``hsr.city``; README "City scale").
"""
from . import _hsr
from ._hsr import *  # noqa: F401,F403  (the public names, listed in __all__)
from ._hsr import __version__  # noqa: F401

__all__ = sorted(name for name in dir(_hsr) if not name.startswith("_"))
# The error type is created inside the compiled module; name it by the package users import.
_hsr.Error.__module__ = "hsr"
