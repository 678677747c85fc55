"""Calibration targets and their detection with OpenCV: chessboards,
ChArUco boards and AprilTag grids (``cv2.aruco``).

A :class:`Target` knows its points in its own frame (z = 0, the board's
units, x to the right and y down the printed image: OpenCV's board frame)
and detects itself in an image, returning the pixels of the points it found
and those points — a partial view for ChArUco and AprilTag grids, whose
markers identify every corner.

Targets are described by a short string (the command line's ``--target``):

* ``chessboard:COLSxROWS:SQUARE`` — inner corners, square size;
* ``charuco:COLSxROWS:SQUARE:MARKER[:DICT]`` — squares, square and marker
  size, the ArUco dictionary (default ``DICT_4X4_50``);
* ``aprilgrid:COLSxROWS:TAG:SPACING[:DICT]`` — tags, tag size and the gap
  between tags as a fraction of the tag size (Kalibr's ``tagSpacing``), the
  dictionary (default ``DICT_APRILTAG_36h11``); tag ids run row by row from
  the top left of the printed grid.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from boxplus._optional import require

__all__ = ["Target", "parse_target"]


def _cv2() -> Any:
    return require("cv2", "target detection")


@dataclass(frozen=True)
class Target:
    """A planar calibration target: ``kind`` ("chessboard", "charuco", "aprilgrid"),
    ``cols`` × ``rows`` (inner corners, squares or tags), ``square`` (square or tag
    size), ``marker`` (ChArUco marker size, or the AprilTag gap as a fraction of
    the tag size) and the ArUco ``dictionary`` name."""

    kind: str
    cols: int
    rows: int
    square: float
    marker: float = 0.0
    dictionary: str = ""

    def __post_init__(self) -> None:
        if self.kind not in ("chessboard", "charuco", "aprilgrid"):
            raise ValueError(f"target kind '{self.kind}' (expected chessboard, charuco or aprilgrid)")
        if self.cols < 2 or self.rows < 2 or not self.square > 0:
            raise ValueError(f"{self.kind}: needs at least 2×2 and a positive size, got "
                             f"{self.cols}x{self.rows}, {self.square}")
        if self.kind == "charuco" and not 0 < self.marker < self.square:
            raise ValueError(f"charuco: the marker size must be in (0, square = {self.square}), "
                             f"got {self.marker}")
        if self.kind == "aprilgrid" and not self.marker >= 0:
            raise ValueError(f"aprilgrid: the spacing must be >= 0, got {self.marker}")

    # ---- geometry -------------------------------------------------------------------
    def points(self) -> np.ndarray:
        """Every point of the target (M, 3), in the order of the detectors' ids."""
        if self.kind == "chessboard":
            g = np.stack(np.meshgrid(np.arange(self.cols), np.arange(self.rows)), -1).reshape(-1, 2)
            return np.column_stack([g * self.square, np.zeros(len(g))])
        return np.asarray(self._board().getChessboardCorners() if self.kind == "charuco"
                          else np.concatenate(self._board().getObjPoints()), float).reshape(-1, 3)

    def _dictionary(self) -> Any:
        cv2 = _cv2()
        name = self.dictionary or ("DICT_4X4_50" if self.kind == "charuco" else "DICT_APRILTAG_36h11")
        if not hasattr(cv2.aruco, name):
            raise ValueError(f"unknown ArUco dictionary '{name}' (e.g. DICT_4X4_50, DICT_APRILTAG_36h11)")
        return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name))

    def _board(self) -> Any:
        cv2 = _cv2()
        if self.kind == "charuco":
            return cv2.aruco.CharucoBoard((self.cols, self.rows), self.square, self.marker,
                                          self._dictionary())
        return cv2.aruco.GridBoard((self.cols, self.rows), self.square, self.square * self.marker,
                                   self._dictionary())

    def image(self, pixels_per_unit: float, margin: int = 20) -> np.ndarray:
        """A printable image of the target (uint8), ``pixels_per_unit`` pixels per board
        unit, white margin of ``margin`` px: the target's point (x, y) is at pixel
        (margin + x·ppu, margin + y·ppu) (corners at pixel corners, OpenCV's convention
        shifted by −0.5)."""
        cv2 = _cv2()
        if self.kind == "chessboard":
            n = int(round(self.square * pixels_per_unit))
            img = np.full(((self.rows + 1) * n, (self.cols + 1) * n), 255, np.uint8)
            for r in range(self.rows + 1):
                for c in range(self.cols + 1):
                    if (r + c) % 2 == 0:
                        img[r * n:(r + 1) * n, c * n:(c + 1) * n] = 0
            return np.pad(img, margin, constant_values=255)
        if self.kind == "charuco":
            wu, hu = self.cols * self.square, self.rows * self.square
        else:
            gap = self.square * self.marker
            wu, hu = (self.cols * self.square + (self.cols - 1) * gap,
                      self.rows * self.square + (self.rows - 1) * gap)
        w, h = int(round(wu * pixels_per_unit)), int(round(hu * pixels_per_unit))
        img = self._board().generateImage((w, h), marginSize=0, borderBits=1)
        return cv2.copyMakeBorder(img, margin, margin, margin, margin, cv2.BORDER_CONSTANT, value=255)

    def image_origin(self, pixels_per_unit: float, margin: int = 20) -> np.ndarray:
        """The pixel of the target's point (0, 0) in :meth:`image` (chessboard: the
        first inner corner)."""
        if self.kind == "chessboard":
            return np.array([margin + self.square * pixels_per_unit - 0.5] * 2)
        return np.array([margin - 0.5] * 2)

    # ---- detection ------------------------------------------------------------------
    def _black_first(self, gray: np.ndarray, c: np.ndarray) -> np.ndarray:
        """The chessboard corners ordered so that the square diagonally outside the
        first corner is black (as in :meth:`image` and OpenCV's pattern.png).

        findChessboardCorners may start from either end: a 180° turn of the board.
        For one camera that is just another board pose, but two cameras of a rig
        must agree on the corners' order. When cols + rows is odd the two ends
        have squares of different colours and fix the order; otherwise the board
        is symmetric and the order is left as found."""
        if (self.cols + self.rows) % 2 == 0:
            return c
        grid = c.reshape(self.rows, self.cols, 2)
        out = grid[0, 0] - 0.5 * (grid[0, 1] - grid[0, 0]) - 0.5 * (grid[1, 0] - grid[0, 0])
        u, v = int(round(out[0])), int(round(out[1]))
        if not (0 <= v < gray.shape[0] and 0 <= u < gray.shape[1]):
            return c
        # its neighbour along the first column: the other colour
        beside = grid[0, 0] - 0.5 * (grid[0, 1] - grid[0, 0]) + 0.5 * (grid[1, 0] - grid[0, 0])
        ui, vi = int(round(beside[0])), int(round(beside[1]))
        if not (0 <= vi < gray.shape[0] and 0 <= ui < gray.shape[1]):
            return c
        return c if int(gray[v, u]) < int(gray[vi, ui]) else c[::-1].copy()

    def detect(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """(pixels (N, 2), target points (N, 3)) found in ``image``, or None (fewer than
        4 points, or for a chessboard not every corner)."""
        cv2 = _cv2()
        gray: Any = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        if self.kind == "chessboard":
            ok, c = cv2.findChessboardCorners(
                gray, (self.cols, self.rows),
                flags=cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
            if not ok:
                return None
            # the refinement window must stay inside the squares around a corner: on a far
            # or oblique board a fixed 15 × 15 window reaches the next corners and biases the
            # result (3 px on a board whose squares are 10 px, rendered with known truth)
            grid = c.reshape(self.rows, self.cols, 2)
            step = min(np.linalg.norm(np.diff(grid, axis=0), axis=2).min(),
                       np.linalg.norm(np.diff(grid, axis=1), axis=2).min())
            win = int(np.clip(0.4 * step, 2, 7))
            crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.01)
            c = cv2.cornerSubPix(gray, c, (win, win), (-1, -1), crit).reshape(-1, 2).astype(float)
            return self._black_first(gray, c), self.points()
        if self.kind == "charuco":
            det = cv2.aruco.CharucoDetector(self._board())
            corners, ids, _, _ = det.detectBoard(gray)
            if ids is None or len(ids) < 4:
                return None
            return corners.reshape(-1, 2).astype(float), self.points()[ids.ravel()]
        det = cv2.aruco.ArucoDetector(self._dictionary())
        params = det.getDetectorParameters()
        params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
        det.setDetectorParameters(params)
        corners, ids, _ = det.detectMarkers(gray)
        if ids is None:
            return None
        n_tags = self.cols * self.rows
        keep = [k for k, i in enumerate(ids.ravel()) if i < n_tags]
        if not keep:
            return None
        P = self.points().reshape(n_tags, 4, 3)
        z = np.concatenate([_refined(gray, corners[k].reshape(4, 2), cv2) for k in keep])
        obj = np.concatenate([P[ids.ravel()[k]] for k in keep])
        return (z, obj) if len(z) >= 4 else None


def _refined(gray: np.ndarray, quad: np.ndarray, cv2: Any) -> np.ndarray:
    """A tag's four corners refined by cornerSubPix in a window of a tenth of its side
    (2–5 px): the detector's own corners sit ~0.5–0.8 px inside the tag's edges (measured
    on images rendered through known poses, boxplus.synthetic.images), the refined ones
    0.2–0.25 px RMS from the truth; a larger window reaches the neighbouring tags."""
    side = float(np.mean(np.linalg.norm(quad - np.roll(quad, 1, axis=0), axis=1)))
    win = int(np.clip(round(0.1 * side), 2, 5))
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 0.001)
    c = cv2.cornerSubPix(gray, quad.astype(np.float32).reshape(-1, 1, 2).copy(), (win, win), (-1, -1),
                         crit)
    return c.reshape(4, 2).astype(float)


def parse_target(spec: str) -> Target:
    """A :class:`Target` from its description (see the module docstring), e.g.
    ``chessboard:9x6:0.025``, ``charuco:7x5:0.04:0.03``, ``aprilgrid:6x6:0.088:0.3``."""
    parts = spec.split(":")
    kind = parts[0]
    need = {"chessboard": 3, "charuco": 4, "aprilgrid": 4}.get(kind)
    if need is None or len(parts) not in (need, need + (kind != "chessboard")):
        raise ValueError(f"target '{spec}': expected chessboard:COLSxROWS:SQUARE, "
                         f"charuco:COLSxROWS:SQUARE:MARKER[:DICT] or "
                         f"aprilgrid:COLSxROWS:TAG:SPACING[:DICT]")
    try:
        cols, rows = (int(v) for v in parts[1].lower().split("x"))
        nums = [float(v) for v in parts[2:need]]
    except ValueError:
        raise ValueError(f"target '{spec}': COLSxROWS must be two integers and the sizes numbers") from None
    return Target(kind, cols, rows, nums[0], nums[1] if len(nums) > 1 else 0.0,
                  parts[need] if len(parts) > need else "")
