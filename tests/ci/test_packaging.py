"""Packaging and lint (issue 23, item 8).

The pip distribution installs every sub-package of textile/
(textile.virtual_tests was left out). .ci/test runs from the source tree
(.ci/build's .pth file), so a package left out of the distribution passes
every other test and breaks only ``pip install .``. .ci/test lints the tree
with flake8 before building and testing."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.installed import import_installed

ROOT = Path(__file__).resolve().parents[2]


def distributed_packages() -> list[str]:
    """The packages ``pip install .`` installs: setup.py run up to its
    configuration (pyproject.toml read; no command run, nothing built)."""
    code = ("import json, setuptools; from distutils.core import run_setup; "
            "print(json.dumps(run_setup('setup.py', stop_after='config').packages))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def source_packages() -> list[str]:
    """Every directory of textile/ with an __init__.py, as a package name."""
    return sorted(".".join(init.parent.relative_to(ROOT).parts)
                  for init in (ROOT / "textile").rglob("__init__.py"))


def test_every_subpackage_is_installed():
    packages = source_packages()
    assert {"textile", "textile.beam", "textile.fabric", "textile.composite", "textile.solver",
            "textile.stability", "textile.effects", "textile.io",
            "textile.virtual_tests"} <= set(packages)
    missing = sorted(set(packages) - set(distributed_packages()))
    assert not missing, f"pyproject.toml does not install {missing}"


def test_every_module_directory_is_a_package():
    """A directory of modules without an __init__.py would be left out of
    the distribution without the test above noticing."""
    dirs = {py.parent for py in (ROOT / "textile").rglob("*.py")}
    assert sorted(str(d.relative_to(ROOT)) for d in dirs if not (d / "__init__.py").exists()) == []


def test_ci_test_lints_before_building_and_testing():
    """.ci/test runs flake8 (installed by .ci/install) on the whole tree,
    and fails on a report, before the build and the tests."""
    text = (ROOT / ".ci" / "test").read_text()
    lint = text.index("if ! /usr/bin/python3 -m flake8; then")
    build = text.index('bash "$root/.ci/build"')
    assert lint < build < text.index("ctest --test-dir") < text.index("-m pytest tests")
    assert "python3-flake8" in (ROOT / ".ci" / "install").read_text().split()


@pytest.mark.parametrize("source,code", [
    ("import os\n", "F401"),                        # unused import
    ("def f():\n    x = 1\n", "F841"),              # unused variable
    ("print(undefined)\n", "F821"),                 # undefined name
    ("x = 1  # " + "." * 91 + "\n", "E501"),        # 100 characters
])
def test_the_lint_reports(tmp_path, source, code):
    """The configuration (.flake8) makes flake8 report each kind of problem
    it is there for; a 99-character line passes."""
    import_installed("flake8", "python3-flake8")
    bad = tmp_path / "bad.py"
    bad.write_text(source)
    good = tmp_path / "good.py"
    good.write_text("x = 1  # " + "." * 90 + "\n")   # 99 characters
    done = subprocess.run([sys.executable, "-m", "flake8", "--config", str(ROOT / ".flake8"),
                           str(bad), str(good)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 1
    assert [line.split()[1] for line in done.stdout.splitlines()] == [code], done.stdout
