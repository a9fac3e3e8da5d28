"""Where gfe-opt writes: ordinary files only, never over an input or without ``force``,
atomically (a crash leaves the old file or the new one, never half of one).

Rules (README "Outputs"): an empty path, a directory, a device, a FIFO or a socket, a path
under /proc, /sys or /dev, or an extension that does not fit the format is refused with one
line; missing parent folders are created; two outputs of one command may not share a path.
"""

from __future__ import annotations

import contextvars
import errno
import os
import shutil
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .errors import GfeInputError

#: the extensions each kind of output is written with
FORMATS = {
    "model": (".toml",),
    "modes": (".json", ".csv", ".uff", ".unv"),
    "report": (".html", ".htm"),
    "figure": (".png",),
}
SYSTEM_TREES = ("/proc", "/sys", "/dev")


def check_output_path(out, force: bool = False, inputs=(), kind: str | None = None,
                      where: str = "--out") -> Path:
    """The path ``out`` if gfe-opt may write there (module docstring), else
    :class:`GfeInputError` naming the option and the fault."""
    if out is None or str(out).strip() == "":
        raise GfeInputError(where, None, "empty path: name the file to write")
    path = Path(out)
    limit = _name_limit(path)
    if len(os.fsencode(path.name)) > limit:
        raise GfeInputError(where, str(path)[:80] + "...", f"its name has "
                            f"{len(os.fsencode(path.name))} bytes; this file system allows "
                            f"{limit}")
    resolved = path.resolve()
    if any(str(resolved) == t or str(resolved).startswith(t + "/") for t in SYSTEM_TREES):
        raise GfeInputError(where, str(path), "lies in a system tree (/proc, /sys, /dev): "
                            "write to an ordinary file")
    for p in inputs:
        if p is not None and Path(p).resolve() == resolved:
            raise GfeInputError(where, str(path), "would overwrite an input file; choose "
                                "another output path")
    exists = path.exists() or path.is_symlink()
    if exists and _file_kind(path) != "file":
        raise GfeInputError(where, str(path), f"is {_file_kind(path)}, not an ordinary file")
    if kind is not None and path.suffix.lower() not in FORMATS[kind]:
        raise GfeInputError(where, str(path), f"a {kind} is written as "
                            f"{' or '.join(FORMATS[kind])}, not {path.suffix or 'no extension'}")
    if exists:
        if not force:
            raise GfeInputError(where, str(path), "exists already; pass --force "
                                "(force=True from Python) to overwrite it")
    parent = path.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if parent.exists() and not parent.is_dir():
        raise GfeInputError(where, str(path), f"{parent} is a file, not a folder")
    return path


def _name_limit(path: Path) -> int:
    """The longest file name the nearest existing folder of ``path`` allows (255 on most)."""
    parent = path.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    try:
        return int(os.pathconf(parent, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return 255


def check_output_folder(folder, where: str = "--plot") -> Path:
    """A folder for figures: absent (it is created) or a folder, never a file."""
    if folder is None or str(folder).strip() == "":
        raise GfeInputError(where, None, "empty path: name the folder for the figures")
    path = Path(folder)
    if path.exists() and not path.is_dir():
        raise GfeInputError(where, str(path), f"is {_file_kind(path)}, not a folder")
    return path


def check_distinct(paths: dict) -> None:
    """Two outputs of one command may not share a path (``paths``: option -> path)."""
    seen = {}
    for option, p in paths.items():
        if p is None:
            continue
        key = Path(p).resolve()
        if key in seen:
            raise GfeInputError(option, str(p), f"is also the path of {seen[key]}: two "
                                "outputs of one command need two paths")
        seen[key] = option


def _file_kind(path: Path) -> str:
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return "a broken link"
    if stat.S_ISREG(mode):
        return "file"
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not an ordinary file"


#: whether a writer may replace an existing file when its caller does not say
#: (:func:`replacing`; the CLI sets it from --force around its writes)
_REPLACE: contextvars.ContextVar = contextvars.ContextVar("gfe_opt_replace", default=True)


@contextmanager
def replacing(allowed: bool):
    """Within this block, writers that are not told otherwise replace existing files only
    if ``allowed`` (a new file is claimed atomically: of two runs, one wins)."""
    token = _REPLACE.set(bool(allowed))
    try:
        yield
    finally:
        _REPLACE.reset(token)


def atomic_write(path, write, *, replace: bool | None = None) -> None:
    """The one writer of every gfe-opt output: ``write(tmp)`` fills a temporary file, which
    then becomes ``path`` in one step, so a crash leaves the old file or the new one.

    The temporary file lies in a private folder made by :func:`tempfile.mkdtemp` in the
    target's folder (mode 0700, an unpredictable name: nobody can plant a link there, and
    its short names never exceed a name limit the output itself keeps); it is synced,
    then renamed onto ``path``, which replaces a link at ``path`` and never writes through
    it.  With ``replace`` false (default: :func:`replacing`, else true) the output must be
    new and is claimed with a hard link, atomically: if anything appeared at ``path`` since
    the checks, this run is refused and the other keeps its file.  A file system that
    refuses is one line naming the path."""
    path = Path(path)
    replace = _REPLACE.get() if replace is None else replace
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GfeInputError(str(path), None, f"cannot create its folder ({exc.strerror})"
                            ) from None
    try:
        private = tempfile.mkdtemp(prefix=".gfe-opt-", dir=path.parent)
    except OSError as exc:
        raise GfeInputError(str(path), None, f"cannot write in its folder ({exc.strerror})"
                            ) from None
    tmp = Path(private) / ("new" + path.suffix.lower())
    try:
        write(tmp)
        fd = os.open(tmp, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        if replace:
            if path.is_dir() and not path.is_symlink():
                raise GfeInputError(str(path), None, "is a directory, not an ordinary file")
            os.replace(tmp, path)
        else:
            _claim(tmp, path)
        _sync_folder(path.parent)
    except OSError as exc:
        raise GfeInputError(str(path), None, f"cannot write ({exc.strerror})") from None
    finally:
        shutil.rmtree(private, ignore_errors=True)


def _claim(tmp: Path, path: Path) -> None:
    """Give ``tmp`` the name ``path`` only if nothing (file or link) has it."""
    exists = GfeInputError(str(path), None, "exists already (another run wrote it meanwhile);"
                           " pass --force (force=True from Python) to overwrite it")
    try:
        os.link(tmp, path)
        return
    except FileExistsError:
        raise exists from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EMLINK):
            raise
    # no hard links on this file system: claim the name with an exclusive create, then
    # rename onto the claimed (empty, ours) file; a failure removes the claim
    try:
        fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY | getattr(os, "O_NOFOLLOW", 0),
                     0o644)
    except FileExistsError:
        raise exists from None
    os.close(fd)
    try:
        os.replace(tmp, path)
    except OSError:
        os.unlink(path)
        raise


def _sync_folder(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def create_exclusive(path, header: str):
    """A new text file opened for appending, created only if nothing (file or link) has its
    name (``O_CREAT | O_EXCL | O_NOFOLLOW``), starting with ``header``; None if it exists."""
    try:
        fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY | os.O_APPEND
                     | getattr(os, "O_NOFOLLOW", 0), 0o644)
    except FileExistsError:
        return None
    handle = os.fdopen(fd, "a", encoding="utf-8")
    handle.write(header + "\n")
    handle.flush()
    return handle


def open_own(path, header: str):
    """An existing file of ``path`` opened for appending if it is an ordinary file (not a
    link) that starts with ``header``; else :class:`GfeInputError`."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_APPEND | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        raise GfeInputError(str(path), None, "exists and is not an ordinary file (a link?); "
                            "remove it or choose another --out") from None
    handle = os.fdopen(fd, "r+", encoding="utf-8", errors="replace")
    if not stat.S_ISREG(os.fstat(fd).st_mode) or handle.readline().rstrip("\n") != header:
        handle.close()
        raise GfeInputError(str(path), None, "exists and is not this batch's journal; "
                            "remove it or choose another --out")
    return handle
