"""Builds the extension module of the Python package with the project's CMake build (only the
front door and the module: no CLI, no tests), for the interpreter that runs pip; with
SURFTRACK_BUILD_DIR=<dir>, takes it from that existing build instead of building anew. The package's
version is CMake's project VERSION, the one the module and the CLI are built with."""
import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        target = Path(self.get_ext_fullpath(ext.name)).resolve()
        existing = os.environ.get("SURFTRACK_BUILD_DIR")
        if existing:
            # A CMake build of this project made already (`cmake -S . -B build`): its module
            # stands alone (python/CMakeLists.txt), and building its target again only brings
            # it up to date.
            build = Path(existing).resolve()
            if not (build / "CMakeCache.txt").is_file():
                raise RuntimeError(f"SURFTRACK_BUILD_DIR={existing}: not a CMake build directory "
                                   "(no CMakeCache.txt); configure it with cmake -S . -B build")
        else:
            build = Path(self.build_temp).resolve() / "cmake"
            build.mkdir(parents=True, exist_ok=True)
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                            "-DSURFTRACK_BUILD_CLI=OFF", "-DSURFTRACK_BUILD_TESTS=OFF",
                            "-DSURFTRACK_SHARED=OFF", f"-DPython3_EXECUTABLE={sys.executable}"],
                           check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "_surftrack", "-j",
                        str(os.cpu_count() or 2)], check=True)
        built = build / "python" / "surftrack" / ("_surftrack" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.is_file():
            raise RuntimeError(f"{build} holds no module for this interpreter ({sys.executable}): "
                               f"configure it with -DPython3_EXECUTABLE={sys.executable}")
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)


def project_version():
    """VERSION of CMakeLists.txt's project(): surftrack.__version__ and `surftrack --version`."""
    match = re.search(r"project\(surftrack\s+VERSION\s+([0-9][0-9.]*)", (ROOT / "CMakeLists.txt").read_text())
    if not match:
        raise RuntimeError("CMakeLists.txt has no project(surftrack VERSION ...)")
    return match.group(1)


setup(version=project_version(), ext_modules=[CMakeExtension("surftrack._surftrack")],
      cmdclass={"build_ext": CMakeBuild})
