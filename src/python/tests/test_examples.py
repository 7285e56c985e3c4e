"""Every numbered example runs (they are the tutorial: docs/python.md), in a scratch folder."""
import glob
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLES = sorted(glob.glob(os.path.join(SOURCE_DIR, "examples", "[0-9][0-9]_*.py")))


def test_examples_exist():
    assert len(EXAMPLES) >= 4


@pytest.mark.parametrize("example", EXAMPLES, ids=os.path.basename)
def test_example_runs(example, tmp_path):
    result = subprocess.run([sys.executable, example, "--small", "--out", str(tmp_path)], cwd=tmp_path,
                            capture_output=True, text=True, timeout=600, env=os.environ.copy())
    assert result.returncode == 0, result.stdout + result.stderr
