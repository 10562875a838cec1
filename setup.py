"""Builds the extension lidarloop._lidarloop with CMake for `pip install .` (docs/python.md).

The library is not compiled twice: when ./build is a CMake build of this checkout with the Python
module on (scripts/setup's release preset) for this interpreter, only the extension target is
built there; otherwise a build of the libraries and the extension alone is configured in
./build-python. LIDARLOOP_CMAKE_BUILD_DIR names another build folder to use.
"""

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
TARGET = "lidarloop_python"


def project_version():
    """The version, written only in project() of CMakeLists.txt."""
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(lidarloop VERSION ([0-9.]+)", text).group(1)


def read_cache(build_dir):
    """CMakeCache.txt as {name: value}; empty when there is none."""
    cache = Path(build_dir) / "CMakeCache.txt"
    if not cache.is_file():
        return {}
    values = {}
    for line in cache.read_text().splitlines():
        match = re.match(r"^([A-Za-z0-9_]+):[A-Z]+=(.*)$", line)
        if match:
            values[match.group(1)] = match.group(2)
    return values


def extension_suffix(python):
    """The file suffix of extension modules for the interpreter `python`."""
    code = "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))"
    return subprocess.run([python, "-c", code], check=True, capture_output=True, text=True).stdout.strip()


def reusable(build_dir):
    """Whether build_dir is configured for this checkout, with the Python module, for an
    interpreter whose extensions this one imports."""
    cache = read_cache(build_dir)
    if not cache or Path(cache.get("CMAKE_HOME_DIRECTORY", "")).resolve() != ROOT:
        return False
    if cache.get("LIDARLOOP_BUILD_PYTHON", "OFF").upper() not in ("ON", "1", "TRUE", "YES"):
        return False
    python = cache.get("Python3_EXECUTABLE", "")
    if not python or not Path(python).exists():
        return False
    return extension_suffix(python) == sysconfig.get_config_var("EXT_SUFFIX")


def configure(build_dir):
    """Configures a build of the libraries and the extension only, for this interpreter."""
    generator = ["-G", "Ninja"] if shutil.which("ninja") else []
    options = {
        "CMAKE_BUILD_TYPE": "Release",
        "LIDARLOOP_BUILD_PYTHON": "ON",
        "LIDARLOOP_BUILD_TESTS": "OFF",
        "LIDARLOOP_BUILD_CLI": "OFF",
        "LIDARLOOP_BUILD_BENCHMARKS": "OFF",
        "LIDARLOOP_BUILD_EXAMPLES": "OFF",
        "LIDARLOOP_WITH_OPEN3D": "OFF",
        "Python3_EXECUTABLE": sys.executable,
    }
    defines = [f"-D{name}={value}" for name, value in options.items()]
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), *generator, *defines], check=True)


def build_dir_to_use():
    chosen = os.environ.get("LIDARLOOP_CMAKE_BUILD_DIR")
    if chosen:
        return Path(chosen).resolve()
    if reusable(ROOT / "build"):
        return ROOT / "build"
    return ROOT / "build-python"


class CMakeBuild(build_ext):
    """Builds the extension target with CMake and copies it into the package."""

    def build_extension(self, ext):
        build_dir = build_dir_to_use()
        if not reusable(build_dir):
            configure(build_dir)
        print(f"lidarloop: building {TARGET} in {build_dir}", flush=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run(
            ["cmake", "--build", str(build_dir), "--target", TARGET, "--parallel", jobs], check=True
        )
        built = build_dir / "python" / "lidarloop" / ("_lidarloop" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.is_file():
            raise RuntimeError(f"{built} was not built (is {build_dir} for another Python?)")
        destination = Path(self.get_ext_fullpath(ext.name))
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, destination)


setup(
    version=project_version(),
    ext_modules=[Extension("lidarloop._lidarloop", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # setuptools' own build folder, away from CMake's ./build.
    options={"build": {"build_base": "build-python/setuptools"}},
)
