"""The C++ half of a Verilator build, made cheap for short runs.

Each Verilator build compiles, besides the design's own C++, Verilator's runtime
(``verilated.cpp``, ``verilated_vpi.cpp``, ...) and cocotb's ``main``: about 25 s of CPU, the
larger part of a small cocotb test. :func:`enable` sets two things for the builds that follow:

* a compile cache: Verilator's makefile calls every compiler through ``$(OBJCACHE)``, which
  becomes this module; it keeps the object files of sources outside the build directory (the
  runtime's, not the design's) and copies them back instead of compiling again;
* the design's C++ at ``-Og`` instead of Verilator's default ``-Os``: five times quicker to
  compile on the whole core (about 8 s of CPU instead of 24 s), and it runs as fast (the XGA
  system run: 39 s against 36 s); ``-O0`` would compile in 4 s but run 2.5 times slower.

The key is what the compiler sees: the command without its output file and the source after
the preprocessor (every header, the design's ``Vtop.h`` for cocotb's ``main`` included), as
ccache's preprocessor mode does. Entries are written whole (write, then rename), so parallel
builds may share the cache.
"""

import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

__all__ = ["enable", "compile_cached", "OPT_FAST"]

#: The optimisation level of the design's C++ (Verilator's ``OPT_FAST``).
OPT_FAST = "-Og"

#: The environment variable naming the cache directory; :func:`enable` sets it.
CACHE_ENV = "DMD_OBJCACHE_DIR"


def enable(directory):
    """Make the Verilator builds started from this process use the compile cache in
    ``directory`` and compile the design at :data:`OPT_FAST`: sets ``OBJCACHE`` and ``OPT_FAST``
    for make through ``MAKEFLAGS`` (whose definitions act as make command-line overrides, in
    every make below) unless already set there, and the cache directory in the environment."""
    directory = Path(directory).resolve()
    directory.mkdir(parents=True, exist_ok=True)
    os.environ[CACHE_ENV] = str(directory)
    # make splits MAKEFLAGS at unescaped spaces; -P: this folder must not shadow the standard library
    wrapper = f"{sys.executable} -P {Path(__file__).resolve()}".replace(" ", "\\ ")
    flags = os.environ.get("MAKEFLAGS", "").split()
    for name, value in (("OBJCACHE", wrapper), ("OPT_FAST", OPT_FAST)):
        if not any(flag.startswith(f"{name}=") for flag in flags):
            flags.append(f"{name}={value}")
    os.environ["MAKEFLAGS"] = " ".join(flags)


def _compile_parts(args):
    """(source, output) of a single ``-c`` compile of a C++ file, else None."""
    if "-c" not in args or "-E" in args:
        return None
    sources = [a for a in args if a.endswith((".cpp", ".cc", ".cxx")) and not a.startswith("-")]
    if len(sources) != 1:
        return None
    source = sources[0]
    output = args[args.index("-o") + 1] if "-o" in args else Path(source).with_suffix(".o").name
    return source, output


def compile_cached(command, cache=None):
    """Run the compiler ``command`` (a list), or copy its output from the cache; returns the
    exit status."""
    cache = cache or os.environ.get(CACHE_ENV)
    parts = _compile_parts(command[1:])
    if cache is None or parts is None:
        return subprocess.call(command)
    source, output = parts
    if Path(source).resolve().is_relative_to(Path.cwd()):
        return subprocess.call(command)      # the design's own C++: compiled once per build anyway
    flags = list(command)
    if "-o" in flags:
        at = flags.index("-o")
        del flags[at:at + 2]
    preprocessed = subprocess.run([a for a in flags if a not in ("-c", "-MMD", "-MD")] + ["-E"],
                                  capture_output=True)
    if preprocessed.returncode != 0:
        return subprocess.call(command)
    key = hashlib.sha256("\0".join(flags).encode() + b"\0" + preprocessed.stdout).hexdigest()
    entry = Path(cache) / key
    depfile = Path(output).with_suffix(".d")
    wants_depfile = "-MMD" in command or "-MD" in command
    if (entry / "object").exists() and (not wants_depfile or (entry / "depfile").exists()):
        shutil.copyfile(entry / "object", output)
        if wants_depfile:
            shutil.copyfile(entry / "depfile", depfile)
        return 0
    status = subprocess.call(command)
    if status == 0:
        staging = Path(cache) / f".{key}.{os.getpid()}"
        staging.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(output, staging / "object")
        if wants_depfile and depfile.exists():
            shutil.copyfile(depfile, staging / "depfile")
        try:
            staging.rename(entry)
        except OSError:          # another build stored it first
            shutil.rmtree(staging, ignore_errors=True)
    return status


if __name__ == "__main__":
    sys.exit(compile_cached(sys.argv[1:]))
