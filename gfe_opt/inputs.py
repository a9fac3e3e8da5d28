"""Reading input files safely: ordinary files only, within a size limit, as UTF-8 text (a
byte-order mark is accepted), and the documented ceilings of a request.

Every fault is one :class:`GfeInputError` naming the file (README "Limits").
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

from .errors import GfeInputError

MiB = 1024 * 1024
#: the largest input files read (refused before they are parsed)
FILE_LIMITS = {"model": 1 * MiB, "measured": 200 * MiB, "results": 4096 * MiB}
#: the finest meshes: beams, the modal solve is verified up to there (gfe_opt.modal); bars,
#: a million elements take 1 GB and 6 s a modal solve, three million fail its check
MAX_ELEMENTS = {"beam": 30_000, "bar": 1_000_000}
#: the most measured modes and sensors in one test
MAX_MEASURED_MODES = 200
MAX_SENSORS = 100_000


def check_input_file(path, what: str) -> Path:
    """``path`` if it is an ordinary file within the size limit for ``what``."""
    path = Path(path)
    where = str(path)
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise GfeInputError(where, None, "no such file") from None
    except OSError as exc:
        raise GfeInputError(where, None, f"cannot read ({exc.strerror})") from None
    if stat.S_ISDIR(info.st_mode):
        raise GfeInputError(where, None, f"is a directory, not a {what} file")
    if not stat.S_ISREG(info.st_mode):
        kind = "a FIFO" if stat.S_ISFIFO(info.st_mode) else "not an ordinary file"
        raise GfeInputError(where, None, f"is {kind}: give a {what} file")
    limit = FILE_LIMITS[what]
    if info.st_size > limit:
        raise GfeInputError(where, None, f"is {info.st_size / MiB:.1f} MB, above the "
                            f"{limit // MiB} MB limit for a {what} file")
    return path


def parse_failure(exc: ValueError) -> str:
    """What a JSON or TOML parser's ``ValueError`` says, in one line: its own message, or
    for an integer longer than Python converts (``sys.get_int_max_str_digits``) that
    number's length, not the interpreter's advice."""
    text = str(exc)
    found = re.search(r"value has (\d+) digits", text)
    if found and "integer string conversion" in text:
        return f"a number of {found.group(1)} digits"
    return text


def read_text(path, what: str) -> str:
    """The text of an input file: checked (:func:`check_input_file`), UTF-8 with or without
    a byte-order mark; binary or UTF-16 files are one line."""
    path = check_input_file(path, what)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise GfeInputError(str(path), None, f"cannot read ({exc.strerror})") from None
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise GfeInputError(str(path), None, "is UTF-16 text: save it as UTF-8")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise GfeInputError(str(path), None, f"is not UTF-8 text (byte {exc.start}: binary "
                            "data?)") from None
    if "\0" in text:
        raise GfeInputError(str(path), None, "contains NUL bytes: not a text file")
    return text
