"""Camera–IMU recordings in ROS bags, read without ROS.

:func:`read_bag` reads the three containers robotics users record in, through the
``rosbags`` package (``pip install 'boxplus[ros]'``):

* ROS 1 bags (``*.bag``), the input of Kalibr's ``kalibr_calibrate_imu_camera``;
* ROS 2 bag folders (``metadata.yaml`` with ``*.db3`` or ``*.mcap``);
* a single MCAP file (``*.mcap``) with ROS 2 messages.

The camera topic carries ``sensor_msgs/Image`` (``mono8``, ``mono16``, ``8UC1``,
``bgr8``, ``rgb8``, ``bgra8``, ``rgba8`` and the 8-bit Bayer encodings) or
``sensor_msgs/CompressedImage`` (anything ``cv2.imdecode`` reads); the IMU topic
``sensor_msgs/Imu`` (``angular_velocity`` in rad/s, ``linear_acceleration`` in m/s²,
both in the IMU's frame). When a topic is not named and the bag has exactly one of
its kind, that one is used; otherwise the error lists the candidates.

Times are the messages' ``header.stamp`` — the sensor's time, as Kalibr uses it — not
the time the recorder received them (which adds transport latency to the time
offset). A topic whose stamps are all zero (some drivers leave them unset) falls back
to the receive time, with a warning. Messages are sorted by stamp (a bag is in
receive order); two messages of one topic with the same stamp are an error naming
both. As in :func:`boxplus.calib.recordings.read_euroc`, times are seconds after the
first IMU stamp, computed from integer nanoseconds.

Images are not held in memory: :meth:`BagRecording.frames` reads the bag again, one
image at a time, so an hour-long recording is detected in constant memory.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BagRecording", "decode_image", "is_bag", "read_bag"]

_IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")
_IMU_TYPE = "sensor_msgs/msg/Imu"


def is_bag(path: str | Path) -> bool:
    """Whether ``path`` looks like a bag :func:`read_bag` reads (by its name, or a ROS 2
    bag folder's ``metadata.yaml``), not like an EuRoC/ASL folder."""
    p = Path(path)
    if p.is_dir():
        return (p / "metadata.yaml").is_file()
    return p.suffix in (".bag", ".mcap", ".db3")


@contextmanager
def _opened(path: Path) -> Iterator[Any]:
    """The bag, open; rosbags' own errors (a bad magic, a truncated chunk, a missing
    metadata key) come out as ValueError naming the file."""
    try:
        with _reader(path) as bag:
            yield bag
    except Exception as e:
        if not type(e).__module__.startswith("rosbags"):
            raise
        raise ValueError(f"{path}: not a bag rosbags can read ({type(e).__name__}: {e})") from None


def _reader(path: Path) -> Any:
    from boxplus._optional import require

    require("rosbags", "reading ROS bags")
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    if not path.exists():
        raise FileNotFoundError(f"{path}: no such bag")
    # ROS 1 bags carry their message definitions; ROS 2's sqlite bags may not, so
    # the standard messages (Humble's) are the fallback
    bag = path.parent if path.suffix == ".db3" else path
    return AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE))


def _topic(path: Path, connections: list[Any], kinds: tuple[str, ...], asked: str | None,
           option: str) -> str:
    """The topic asked for (checked), or the only topic of one of ``kinds``."""
    have = {c.topic: c.msgtype for c in connections}
    if asked is not None:
        if asked not in have:
            listing = ", ".join(f"{t} ({m})" for t, m in sorted(have.items())) or "none"
            raise ValueError(f"{path}: no topic '{asked}' (topics: {listing})")
        if have[asked] not in kinds:
            raise ValueError(f"{path}: topic '{asked}' carries {have[asked]}, not "
                             f"{' or '.join(kinds)}")
        return asked
    found = sorted(t for t, m in have.items() if m in kinds)
    if len(found) == 1:
        return found[0]
    what = " or ".join(kinds)
    if not found:
        raise ValueError(f"{path}: no topic of type {what}")
    raise ValueError(f"{path}: {len(found)} topics of type {what} ({', '.join(found)}); "
                     f"name one with {option}")


def _stamp_ns(message: Any) -> int:
    s = message.header.stamp
    return int(s.sec) * 1_000_000_000 + int(s.nanosec)


def _times(path: Path, topic: str, header_ns: list[int], received_ns: list[int]) -> np.ndarray:
    """The topic's stamps (ns): the headers', or the receive times when all are zero."""
    stamps = np.array(header_ns, dtype=np.int64)
    if stamps.size and not stamps.any():
        warnings.warn(f"{path}: every header.stamp of '{topic}' is zero; using the times the "
                      f"recorder received the messages (they include transport latency)",
                      stacklevel=3)
        stamps = np.array(received_ns, dtype=np.int64)
    return stamps


def _sorted_unique(path: Path, topic: str, stamps: np.ndarray) -> np.ndarray:
    """The order that sorts ``stamps``; an error when two are equal."""
    order = np.argsort(stamps, kind="stable")
    s = stamps[order]
    same = np.flatnonzero(np.diff(s) == 0)
    if same.size:
        i, j = order[same[0]], order[same[0] + 1]
        raise ValueError(f"{path}: topic '{topic}': messages {i} and {j} have the same stamp "
                         f"{s[same[0]]} ns")
    return order


def decode_image(message: Any, msgtype: str) -> np.ndarray:
    """A ``sensor_msgs`` Image or CompressedImage as an 8-bit grey image (what the
    target detectors take); ValueError for an encoding it does not know."""
    from boxplus._optional import require

    cv2 = require("cv2", "decoding camera images")
    if msgtype.endswith("CompressedImage"):
        gray = cv2.imdecode(np.frombuffer(bytes(message.data), np.uint8), cv2.IMREAD_GRAYSCALE)
        if gray is None:
            raise ValueError(f"a CompressedImage ('{message.format}') OpenCV cannot decode")
        return gray
    enc, h, w, step = str(message.encoding).lower(), int(message.height), int(message.width), int(message.step)
    raw = np.frombuffer(bytes(message.data), np.uint8)
    channels = {"mono8": 1, "8uc1": 1, "mono16": 2, "16uc1": 2, "bgr8": 3, "rgb8": 3,
                "8uc3": 3, "bgra8": 4, "rgba8": 4, "8uc4": 4}
    bayer = {"bayer_rggb8": cv2.COLOR_BayerRG2GRAY, "bayer_bggr8": cv2.COLOR_BayerBG2GRAY,
             "bayer_gbrg8": cv2.COLOR_BayerGB2GRAY, "bayer_grbg8": cv2.COLOR_BayerGR2GRAY}
    bytes_per_pixel = 1 if enc in bayer else channels.get(enc)
    if bytes_per_pixel is None:
        raise ValueError(f"image encoding '{message.encoding}' (boxplus reads mono8, mono16, "
                         f"bgr8, rgb8, bgra8, rgba8, 8-bit Bayer and CompressedImage)")
    if step < w * bytes_per_pixel or raw.size < step * h:
        raise ValueError(f"a {w}×{h} '{enc}' image with step {step} and {raw.size} bytes of data")
    rows = raw[: step * h].reshape(h, step)[:, : w * bytes_per_pixel]
    if enc in bayer:
        return cv2.cvtColor(np.ascontiguousarray(rows), bayer[enc])
    if bytes_per_pixel == 2:
        order = ">u2" if message.is_bigendian else "<u2"
        img16 = np.ascontiguousarray(rows).view(order).reshape(h, w).astype(np.float64)
        top = img16.max()
        # 10- and 12-bit sensors fill only part of the 16 bits: stretch to 8 bits
        return (img16 * (255.0 / top)).round().astype(np.uint8) if top > 0 else np.zeros((h, w), np.uint8)
    pixels = np.ascontiguousarray(rows).reshape(h, w, bytes_per_pixel)
    if bytes_per_pixel == 1:
        return pixels[:, :, 0]
    code = {"rgb8": cv2.COLOR_RGB2GRAY, "rgba8": cv2.COLOR_RGBA2GRAY, "bgra8": cv2.COLOR_BGRA2GRAY,
            "8uc4": cv2.COLOR_BGRA2GRAY}.get(enc, cv2.COLOR_BGR2GRAY)
    return cv2.cvtColor(pixels, code)


@dataclass
class BagRecording:
    """A camera topic's frame times and an IMU topic's samples from a bag; times in
    seconds after ``origin_ns`` (the first IMU stamp). The images stay in the bag:
    :meth:`frames` reads them."""

    path: Path
    image_topic: str
    imu_topic: str
    frame_times: np.ndarray   # (F,) s
    imu_times: np.ndarray     # (N,) s
    gyro: np.ndarray          # (N, 3) rad/s
    accel: np.ndarray         # (N, 3) m/s²
    origin_ns: int
    _frame_order: np.ndarray = field(repr=False)   # bag position of the k-th frame by stamp

    def frames(self) -> Iterator[tuple[str, np.ndarray]]:
        """(a name for messages, the grey image) of every frame, in time order."""
        rank = np.empty_like(self._frame_order)
        rank[self._frame_order] = np.arange(self._frame_order.size)
        pending: dict[int, tuple[str, np.ndarray]] = {}
        emitted = 0
        with _opened(self.path) as bag:
            conns = [c for c in bag.connections if c.topic == self.image_topic]
            for i, (conn, _, raw) in enumerate(bag.messages(connections=conns)):
                name = f"{self.path}: '{self.image_topic}' message {i}"
                try:
                    gray = decode_image(bag.deserialize(raw, conn.msgtype), conn.msgtype)
                except ValueError as e:
                    raise ValueError(f"{name}: {e}") from None
                pending[int(rank[i])] = (name, gray)
                # stamps are nearly in bag order: only the few out of order wait here
                while emitted in pending:
                    yield pending.pop(emitted)
                    emitted += 1


def read_bag(path: str | Path, image_topic: str | None = None,
             imu_topic: str | None = None) -> BagRecording:
    """The camera and IMU topics of a ROS 1 bag, a ROS 2 bag folder or an MCAP file
    (module docstring); a topic may be left out when the bag has only one of its kind."""
    p = Path(path)
    with _opened(p) as bag:
        conns = list(bag.connections)
        cam = _topic(p, conns, _IMAGE_TYPES, image_topic, "--image-topic")
        imu = _topic(p, conns, (_IMU_TYPE,), imu_topic, "--imu-topic")
        img_header: list[int] = []
        img_received: list[int] = []
        imu_header: list[int] = []
        imu_received: list[int] = []
        values: list[tuple[float, ...]] = []
        chosen = [c for c in conns if c.topic in (cam, imu)]
        for conn, received, raw in bag.messages(connections=chosen):
            msg = bag.deserialize(raw, conn.msgtype)
            if conn.topic == cam:
                img_header.append(_stamp_ns(msg))
                img_received.append(int(received))
            else:
                w, a = msg.angular_velocity, msg.linear_acceleration
                values.append((w.x, w.y, w.z, a.x, a.y, a.z))
                imu_header.append(_stamp_ns(msg))
                imu_received.append(int(received))
    if not values:
        raise ValueError(f"{p}: topic '{imu}' has no messages")
    if not img_header:
        raise ValueError(f"{p}: topic '{cam}' has no messages")
    imu_ns = _times(p, imu, imu_header, imu_received)
    cam_ns = _times(p, cam, img_header, img_received)
    imu_order = _sorted_unique(p, imu, imu_ns)
    cam_order = _sorted_unique(p, cam, cam_ns)
    samples = np.array(values, dtype=float)[imu_order]
    bad = np.flatnonzero(~np.all(np.isfinite(samples), axis=1))
    if bad.size:
        raise ValueError(f"{p}: topic '{imu}': message {imu_order[bad[0]]} has a non-finite "
                         f"angular velocity or linear acceleration")
    origin = int(imu_ns[imu_order[0]])
    return BagRecording(p, cam, imu, (cam_ns[cam_order] - origin) * 1e-9,
                        (imu_ns[imu_order] - origin) * 1e-9, samples[:, :3], samples[:, 3:],
                        origin, cam_order)
