"""Optional dependencies, imported when first used, with an error that names
the extra to install (``pip install 'boxplus[<extra>]'``) instead of a bare
ModuleNotFoundError from deep inside a call."""

from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["EXTRAS", "require"]

# module → (extra of pyproject.toml's [project.optional-dependencies], what it is)
EXTRAS = {
    "cv2": ("calib", "OpenCV (opencv-python-headless)"),
    "matplotlib": ("plot", "matplotlib"),
    "yaml": ("yaml", "PyYAML"),
    "ray": ("ray", "Ray"),
    "distributed": ("dask", "Dask distributed"),
    "tqdm": ("progress", "tqdm"),
    "rosbags": ("ros", "rosbags"),
    "mcap": ("ros", "mcap"),
}


def require(module: str, purpose: str) -> ModuleType:
    """``module`` imported, or ImportError: '<purpose> needs <what>: pip install ...'."""
    try:
        return importlib.import_module(module)
    except ImportError:
        top = module.split(".")[0]
        extra, what = EXTRAS.get(top, (None, top))
        how = f"pip install 'boxplus[{extra}]'" if extra else f"pip install {top}"
        raise ImportError(f"{purpose} needs {what}: {how}") from None
