"""What the Python tests share: the CLI executable, the data folders, running the CLI.

CTest (tests/CMakeLists.txt) sets PYTHONPATH to the built module, CHEVAL_EXE to the `cheval`
executable, CHEVAL_DATA_DIR to the shared real data and CHEVAL_TEST_DATA_DIR to tests/data.
"""

import os
import subprocess
import sys
import unittest

SKIP = 77  # CTest's SKIP_RETURN_CODE for the tests that need the shared data

CLI = os.environ.get("CHEVAL_EXE", "cheval")
TEST_DATA = os.environ.get("CHEVAL_TEST_DATA_DIR",
                           os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data"))
DATA = os.environ.get("CHEVAL_DATA_DIR",
                      os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))


def run_cli(*args, cwd=None):
    """Runs the CLI; returns (exit code, stdout, stderr)."""
    done = subprocess.run([CLI, *map(str, args)], cwd=cwd, capture_output=True, text=True, check=False)
    return done.returncode, done.stdout, done.stderr


def main_needing(folder):
    """unittest.main(), or exit 77 (skipped) when `folder` is missing outside CI. In CI
    (CI set and not 'false') a missing folder fails the run."""
    if not os.path.isdir(folder):
        if os.environ.get("CI", "").lower() not in ("", "0", "false"):
            sys.exit(f"{folder} is missing and CI is set: the data tests must run in CI")
        print(f"skipped: {folder} is missing (set CHEVAL_DATA_DIR)")
        sys.exit(SKIP)
    unittest.main()
