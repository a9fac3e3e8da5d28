"""Run every command the README shows, as a reader would paste it (run by ``.ci/run``).

    python scripts/check_readme.py [README.md]

Every fenced ``bash`` block is run line by line (a trailing backslash continues a line;
``# ...`` comments are dropped) and every fenced ``python`` block as one program, in order,
in one fresh temporary folder holding links to ``problems/``, ``scripts/`` and ``tests/``
(so what the commands write never lands in the repository).  Two things are left out, and
said: ``pip install ... &&`` in front of a command (CI has installed the project already),
and ``python -m pytest`` (CI runs it).  A block that cannot run as written carries the
line ``<!-- check_readme: skip: REASON -->`` just above it.  Each command must exit 0;
the script prints each with its time and exits 1 when one did not.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SKIP = re.compile(r"<!--\s*check_readme:\s*skip:\s*(.+?)\s*-->")
INSTALL = re.compile(r"^pip install [^&]*&&\s*")


def blocks(text: str):
    """(language, code, skip reason or None, line number) of every bash/python block."""
    lines = text.splitlines()
    found, i = [], 0
    while i < len(lines):
        m = re.match(r"^\s*```(\w+)\s*$", lines[i])
        if not m:
            i += 1
            continue
        start, lang = i, m.group(1)
        j = i + 1
        while j < len(lines) and not lines[j].strip().startswith("```"):
            j += 1
        k = start - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        skip = SKIP.search(lines[k]) if k >= 0 else None
        if lang in ("bash", "python"):
            found.append((lang, "\n".join(lines[start + 1:j]), skip.group(1) if skip else None,
                          start + 1))
        i = j + 1
    return found


def commands(code: str) -> list[str]:
    """The shell commands of a bash block: continuations joined, comments dropped."""
    out, current = [], ""
    for line in code.splitlines():
        if line.rstrip().endswith("\\"):
            current += line.rstrip()[:-1] + " "
            continue
        line = re.sub(r"\s+#.*$", "", current + line).strip()
        current = ""
        if line and not line.startswith("#"):
            out.append(line)
    return out


def main() -> int:
    readme = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "README.md"
    failed = 0
    with tempfile.TemporaryDirectory(prefix="readme-") as tmp:
        for name in ("problems", "scripts", "tests"):
            (Path(tmp) / name).symlink_to(ROOT / name)
        for lang, code, skip, line in blocks(readme.read_text(encoding="utf-8")):
            if skip:
                print(f"README.md:{line}: {lang} block skipped: {skip}")
                continue
            runs = ([["python", "-c", code]] if lang == "python" else
                    [["bash", "-c", c] for c in commands(code)])
            for argv in runs:
                shown = argv[2].splitlines()[0] if lang == "bash" else f"python block (line {line})"
                if lang == "bash":
                    stripped = INSTALL.sub("", argv[2])
                    if stripped != argv[2]:
                        print(f"README.md:{line}: left out (CI installed the project): "
                              f"{argv[2][:len(argv[2]) - len(stripped)].strip()}")
                        argv, shown = ["bash", "-c", stripped], stripped
                    if stripped.startswith("python -m pytest"):
                        print(f"README.md:{line}: left out (CI runs it): {stripped}")
                        continue
                start = time.perf_counter()
                done = subprocess.run(argv, cwd=tmp, capture_output=True, text=True)
                seconds = time.perf_counter() - start
                status = "ok" if done.returncode == 0 else f"FAILED (exit {done.returncode})"
                print(f"README.md:{line}: {status} {seconds:6.1f} s  {shown}", flush=True)
                if done.returncode != 0:
                    failed += 1
                    print((done.stdout[-2000:] + done.stderr[-2000:]).rstrip())
    print(f"{failed} README command(s) failed" if failed else "every README command ran")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
