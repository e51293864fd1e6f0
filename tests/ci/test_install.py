""".ci/install on machines of both kinds, without touching this one's
packages: ``dpkg-query``, ``apt-get`` and ``sudo`` are replaced on PATH by
fakes that answer from a list of installed packages and record what apt was
asked to do.

The two kinds (project issue 22, item 6): a machine with python3-vtk9, and
one with ParaView's Python (python3-paraview, which ships the same
vtkmodules and, on Debian 12, conflicts with python3-vtk9). On the second,
the install must not ask for python3-vtk9 (apt would remove
python3-paraview to install it); whatever it installs, apt runs with
--no-remove, so a conflict fails the install instead of removing a package.
"""
import os
import re
import stat
import subprocess
from pathlib import Path

import pytest

INSTALL = Path(__file__).resolve().parents[2] / ".ci" / "install"


def required() -> list[str]:
    """Every package the script may install, first alternatives only (read
    from the script's ``need`` lines, so the test follows the list)."""
    text = re.sub(r"\\\n", " ", INSTALL.read_text())
    names = []
    for line in text.splitlines():
        if line.startswith("need "):
            specs = re.sub(r'"[^"]*"', "", line[5:], count=1).split()
            names += [s.strip('"').split("|")[0] for s in specs]
    return names


def run_install(tmp_path, installed, apt_fails=False):
    """Run .ci/install with fake tools; returns (completed process, the
    apt-get calls as argument lists)."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (tmp_path / "installed").write_text("\n".join(installed) + "\n")
    log = tmp_path / "apt.log"
    fakes = {
        # dpkg-query -W -f='${Status}' NAME
        "dpkg-query": f"""#!/bin/sh
for a; do name="$a"; done
if grep -qx "$name" "{tmp_path}/installed"; then printf 'install ok installed'; exit 0; fi
echo "dpkg-query: no packages found matching $name" >&2; exit 1
""",
        "apt-get": f"""#!/bin/sh
echo "$*" >> "{log}"
if [ "$1" = install ] && [ -n "{'1' if apt_fails else ''}" ]; then
  echo "E: Packages need to be removed but remove is disabled." >&2; exit 100
fi
exit 0
""",
        "sudo": '#!/bin/sh\nexec "$@"\n',
    }
    for name, text in fakes.items():
        path = bin_dir / name
        path.write_text(text)
        path.chmod(path.stat().st_mode | stat.S_IXUSR)
    env = dict(os.environ, PATH=f"{bin_dir}:{os.environ['PATH']}")
    done = subprocess.run(["bash", str(INSTALL)], env=env, capture_output=True, text=True,
                          timeout=60)
    calls = [line.split() for line in log.read_text().splitlines()] if log.exists() else []
    return done, calls


def installs(calls) -> list[str]:
    """Packages of the apt-get install call (options dropped)."""
    (call,) = [c for c in calls if c[0] == "install"]
    return [a for a in call[1:] if not a.startswith("-")]


def everything_but(*absent, extra=()):
    return [p for p in required() if p not in absent] + list(extra)


def test_the_list_is_read():
    """The fakes' package list comes from the script (a control for the
    tests below: they would pass vacuously on an empty list)."""
    names = required()
    assert "python3-vtk9" in names and "python3-dolfinx" in names
    assert "python3-paraview" not in names      # an alternative, never installed
    assert len(names) > 20


def test_complete_machine_installs_nothing(tmp_path):
    done, calls = run_install(tmp_path, everything_but())
    assert done.returncode == 0, done.stderr
    assert "all Debian packages present" in done.stdout
    assert calls == []


def test_paraview_machine_keeps_paraview(tmp_path):
    """python3-paraview present, python3-vtk9 absent: VTK is there, nothing
    to install; the output says why python3-vtk9 is not installed."""
    done, calls = run_install(tmp_path, everything_but("python3-vtk9",
                                                       extra=["python3-paraview"]))
    assert done.returncode == 0, done.stderr
    assert calls == []
    assert "python3-vtk9 not needed: python3-paraview is installed" in done.stdout


def test_paraview_machine_missing_something_else(tmp_path):
    """The same machine without h5py: only h5py is installed, with
    --no-remove, and the reason is printed."""
    done, calls = run_install(tmp_path, everything_but("python3-vtk9", "python3-h5py",
                                                       extra=["python3-paraview"]))
    assert done.returncode == 0, done.stderr
    assert installs(calls) == ["python3-h5py"]
    (call,) = [c for c in calls if c[0] == "install"]
    assert "--no-remove" in call and "-y" in call
    assert re.search(r"python3-h5py: .*state files", done.stdout)


def test_machine_without_vtk_gets_vtk9(tmp_path):
    """Neither provider: python3-vtk9 is installed (with --no-remove), and
    the output names both providers."""
    done, calls = run_install(tmp_path, everything_but("python3-vtk9"))
    assert done.returncode == 0, done.stderr
    assert installs(calls) == ["python3-vtk9"]
    assert "--no-remove" in [c for c in calls if c[0] == "install"][0]
    assert "python3-vtk9: VTK's Python modules" in done.stdout
    assert "none of python3-vtk9, python3-paraview is installed" in done.stdout


def test_bare_machine_installs_every_first_alternative(tmp_path):
    done, calls = run_install(tmp_path, [])
    assert done.returncode == 0, done.stderr
    assert installs(calls) == required()
    assert ["update", "-q"] in calls


def test_a_refusing_apt_fails_the_install(tmp_path):
    """apt refusing (a conflict it may not solve by removing a package) is
    a failure of the install, with words, not a silent success."""
    done, calls = run_install(tmp_path, everything_but("python3-vtk9"), apt_fails=True)
    assert done.returncode != 0
    assert "nothing was removed" in done.stderr
    assert installs(calls) == ["python3-vtk9"]


@pytest.mark.parametrize("script", ["demo", "test"])
def test_entry_points_go_through_install(script):
    """.ci/demo and .ci/test install through this script only (no apt-get
    of their own that could remove a package)."""
    text = (INSTALL.parent / script).read_text()
    assert 'bash "$root/.ci/install"' in text and "apt-get" not in text
