"""tests/installed.py: a test needing a package .ci/install installs is
skipped where the package is missing, but fails under .ci/test
(TEXTILE_INSTALLED=1): a broken install cannot pass CI as skipped tests."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CASE = '''
from tests.installed import import_installed, needs

def test_import():
    import_installed("textile_no_such_module", "no-such-package")

@needs(False, "a package that is not here")
def test_marker():
    assert False, "ran without the package"
'''


@pytest.mark.parametrize("required,outcome", [("", "2 skipped"), ("1", "2 failed")])
def test_missing_package_skips_or_fails(tmp_path, required, outcome):
    case = tmp_path / "test_case.py"
    case.write_text(CASE)
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(ROOT), "TEXTILE_INSTALLED": required}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           str(case)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120)
    assert outcome in done.stdout, done.stdout + done.stderr


def test_ci_test_requires_the_installed_packages():
    assert "export TEXTILE_INSTALLED=1" in (ROOT / ".ci" / "test").read_text()
