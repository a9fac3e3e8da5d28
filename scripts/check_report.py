"""Render an HTML report in headless Chromium and save a screenshot to look at.

    python scripts/check_report.py REPORT.html [SCREENSHOT.png]

Needs Debian's chromium (``apt-get install chromium``); without it the script says so and
exits 1.  The screenshot is what a colleague would see when opening the report.
"""

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    report = Path(sys.argv[1]).resolve()
    shot = Path(sys.argv[2] if len(sys.argv) > 2 else report.with_suffix(".png")).resolve()
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        print("chromium is not installed: apt-get install chromium")
        return 1
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu",
                        "--disable-quic", "--no-first-run", "--disable-background-networking",
                        "--disable-component-update", "--disable-sync",
                        f"--user-data-dir={profile}", "--hide-scrollbars",
                        "--window-size=1200,3000", f"--screenshot={shot}",
                        report.as_uri()], check=True, capture_output=True, timeout=120)
    print(f"screenshot: {shot} ({shot.stat().st_size} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
