"""Where gfe-opt writes: ordinary files only, never over an input or without ``force``,
atomically (a crash leaves the old file or the new one, never half of one).

Rules (README "Outputs"): an empty path, a directory, a device, a FIFO or a socket, a path
under /proc, /sys or /dev, or an extension that does not fit the format is refused with one
line; missing parent folders are created; two outputs of one command may not share a path.
"""

from __future__ import annotations

import os
import stat
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


def atomic_write(path, write) -> None:
    """Call ``write(tmp_path)`` and move the result onto ``path`` in one step (missing
    folders created); a file system that refuses is one line naming the path."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GfeInputError(str(path), None, f"cannot create its folder ({exc.strerror})"
                            ) from None
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        write(tmp)
        os.replace(tmp, path)
    except OSError as exc:
        raise GfeInputError(str(path), None, f"cannot write ({exc.strerror})") from None
    finally:
        if tmp.exists():
            tmp.unlink()
