"""The pip distribution installs every sub-package of textile/ (issue 23,
item 8: textile.virtual_tests was left out). .ci/test runs from the source
tree (.ci/build's .pth file), so a package left out of the distribution
passes every other test and breaks only ``pip install .``."""
import json
import subprocess
import sys
from pathlib import Path

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
    assert {"textile", "textile.effects", "textile.io", "textile.virtual_tests"} <= set(packages)
    missing = sorted(set(packages) - set(distributed_packages()))
    assert not missing, f"pyproject.toml does not install {missing}"


def test_every_module_directory_is_a_package():
    """A directory of modules without an __init__.py would be left out of
    the distribution without the test above noticing."""
    dirs = {py.parent for py in (ROOT / "textile").rglob("*.py")}
    assert sorted(str(d.relative_to(ROOT)) for d in dirs if not (d / "__init__.py").exists()) == []
