"""The fuzzer for longer: tests/test_fuzz.py with the ``long`` hypothesis profile (30 000
mutated files and 30 000 option strings through the command line), or another profile.

    python scripts/fuzz.py [--profile long]
"""

import argparse
import subprocess
import sys
from pathlib import Path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", default="long", help="hypothesis profile (ci, long)")
    args = parser.parse_args()
    root = Path(__file__).resolve().parents[1]
    return subprocess.call([sys.executable, "-m", "pytest", "-q", "tests/test_fuzz.py",
                            f"--hypothesis-profile={args.profile}",
                            "-p", "no:cacheprovider"], cwd=root)


if __name__ == "__main__":
    sys.exit(main())
