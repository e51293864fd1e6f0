"""pip build: runs CMake for the C++ module (pattern of dolfinx 0.5.2's setup.py).

Use Debian's tools: /usr/bin/python3 -m venv --system-site-packages .venv &&
.venv/bin/pip install --no-build-isolation --no-deps .
"""
import os
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class CMakeExtension(Extension):
    def __init__(self, name, sourcedir=""):
        super().__init__(name, sources=[])
        self.sourcedir = os.path.abspath(sourcedir)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        extdir = os.path.abspath(os.path.dirname(self.get_ext_fullpath(ext.name)))
        args = [f"-DCMAKE_LIBRARY_OUTPUT_DIRECTORY={extdir}",
                f"-DPython3_EXECUTABLE={sys.executable}",
                "-DTEXTILE_BUILD_TESTS=OFF",
                f"-DCMAKE_BUILD_TYPE={os.environ.get('CMAKE_BUILD_TYPE', 'Release')}"]
        os.makedirs(self.build_temp, exist_ok=True)
        subprocess.check_call(["cmake", ext.sourcedir, *args], cwd=self.build_temp)
        subprocess.check_call(["cmake", "--build", ".", "--parallel"], cwd=self.build_temp)


setup(ext_modules=[CMakeExtension("textile._cpp")], cmdclass={"build_ext": CMakeBuild})
