"""Tests that need a package `.ci/install` installs (VTK's Python modules,
xvfb): skipped where it is missing, except under `.ci/test`, which sets
TEXTILE_INSTALLED=1 after running the install. There a missing package is a
broken install, and the test fails instead of passing as skipped."""
import importlib
import os

import pytest

#: True under .ci/test: every package .ci/install installs must be present
REQUIRED = os.environ.get("TEXTILE_INSTALLED") == "1"


def missing(what: str) -> None:
    """Skip the current test, or fail it under .ci/test."""
    message = f"{what} (.ci/install installs it)"
    if REQUIRED:
        pytest.fail(f"{message}: missing although TEXTILE_INSTALLED=1", pytrace=False)
    pytest.skip(message)


def import_installed(module: str, package: str):
    """``module`` imported, or the test skipped (failed under .ci/test)."""
    try:
        return importlib.import_module(module)
    except ImportError:
        missing(f"{module} cannot be imported: Debian package {package}")


def needs(available: bool, what: str):
    """Marker: skip unless ``available``; under .ci/test never skip (the
    test then runs and fails on what is missing)."""
    return pytest.mark.skipif(not available and not REQUIRED,
                              reason=f"{what} (.ci/install installs it)")
