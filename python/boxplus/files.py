"""Writing files without ever losing the user's data.

Every file boxplus writes from Python goes through :func:`atomic_path` (or
:func:`write_atomically`): the content is written to a temporary file in the
target's own folder, flushed to disk, and renamed over the target only when
all of it was written. A failed write (a full disk, a closed pipe, an
exception in the code producing the content) removes the temporary, leaves
any previous file of that name as it was, and raises :class:`OSError` naming
the target — never a truncated or empty result beside a success message.

:func:`refuse_overwriting` keeps a tool from writing over one of its own
inputs (the same file through any path, link or symlink).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Union

__all__ = ["atomic_path", "refuse_overwriting", "same_file", "save_figure", "write_atomically"]

PathLike = Union[str, "os.PathLike[str]"]


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """A temporary path in ``path``'s folder to write to; renamed over ``path`` when the
    block ends without an exception, removed otherwise.

    Examples
    --------
    >>> with atomic_path("figure.png") as tmp:      # doctest: +SKIP
    ...     fig.savefig(tmp, format="png")
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if target.is_dir():
        raise IsADirectoryError(f"cannot write '{target}': it is a folder")
    if target.exists() and not target.is_file():
        # A device, pipe or socket (/dev/stdout, /dev/full, a FIFO): there is no file to
        # replace, so the content goes to it directly, and its write errors are raised.
        yield target
        return
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    except OSError as e:
        raise OSError(e.errno, f"cannot write '{target}': {e.strerror}") from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        with open(tmp, "rb+") as f:  # the content on disk before the rename makes it visible
            os.fsync(f.fileno())
        if target.exists():  # keep the mode of the file being replaced
            os.chmod(tmp, target.stat().st_mode & 0o7777)
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except OSError as e:
        tmp.unlink(missing_ok=True)
        if str(target) in str(e):
            raise
        raise OSError(e.errno, f"cannot write '{target}': {e.strerror or e}") from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_atomically(path: PathLike, content: str | bytes, encoding: str = "utf-8") -> None:
    """Writes ``content`` (text or bytes) to ``path`` atomically (:func:`atomic_path`)."""
    data = content.encode(encoding) if isinstance(content, str) else content
    with atomic_path(path) as tmp:
        try:
            with open(tmp, "wb") as f:
                f.write(data)
                f.flush()
        except OSError as e:
            raise OSError(e.errno, f"cannot write '{path}': {e.strerror or e}") from None


def save_figure(fig: object, path: PathLike, **savefig_kw: object) -> None:
    """``fig.savefig`` (a matplotlib Figure) through :func:`atomic_path`; the format is
    taken from ``path``'s suffix (the temporary file has none)."""
    fmt = Path(path).suffix.lstrip(".").lower() or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **savefig_kw)  # type: ignore[attr-defined]


def same_file(a: PathLike, b: PathLike) -> bool:
    """Whether two paths name one existing file (device and inode: links and symlinks too)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def refuse_overwriting(output: PathLike, inputs: Iterable[PathLike], tool: str,
                       flag: str = "--overwrite-input") -> None:
    """Raises ValueError when ``output`` names one of ``inputs`` (files or folders; the
    same file through any path, link or symlink), naming both and the flag that allows it."""
    for src in inputs:
        if same_file(output, src):
            raise ValueError(f"{tool}: the output '{output}' is the input '{src}'; give another "
                             f"output, or {flag} to write into it")
