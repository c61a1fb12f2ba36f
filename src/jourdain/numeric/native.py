"""What ``-march=native`` means on this machine, asked of the compiler once per machine rather
than once per process (issue 35, item 3: a warm start in milliseconds).

Every cache key holds the native target (:func:`jourdain.numeric.toolchain.content_key`), and
asking the compiler's driver for it (:func:`ask_target`) starts a process: 7-8 ms of every
warm start on the 2-core test machine, a third of what was left of it after the imports. The
answer depends on the compiler and on the processor only, so it is kept in the cache under a
key of both (:func:`machine_key`): the compiler's resolved path, size and time of change, the
flags asked about, and the processor's identity as the kernel reports it (vendor, family,
model, stepping, microcode, cache size and instruction-set flags from ``/proc/cpuinfo``). A
cache shared by machines of different processors (a home folder on a cluster) therefore keeps
one answer per processor, and a changed compiler is asked again. Where ``/proc/cpuinfo``
cannot be read, nothing is kept and the compiler is asked in every process, as before.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
from pathlib import Path

from .cachefile import keep_sealed, read_sealed

#: x86: no instruction set that holds a fused multiply-add (FMA3, FMA4, and AVX-512, which has
#: them at every vector length). ``-ffp-contract=off`` keeps the compiler from fusing a product
#: and a sum that the source writes apart, but GCC 12's vectorizer does not ask it there: its
#: SLP pattern for lanes that add and subtract the same operands takes a product in as
#: ``vfmaddsub``/``vfmsubadd`` (GCC 12.2 -O2, -march=native on an AVX-512 machine and
#: -march=skylake-avx512; later GCC checks the flag). One rounding fewer: ``random_tree(70,
#: seed=3)``'s ÿ differed from the -O0 and -O1 builds' (and the first runs') by up to 6e-13 at
#: 15 of 200 states, and a dozen libraries in this machine's caches held such instructions
#: (a tutorial's model among them; tests/test_native.py). Without these sets no vectorizer
#: can form one. Against the build with them (2-core AMD EPYC, GCC 12.2, the two alternated):
#: batches of M, k, q 0.83-1.09× the time (five models, one process); the 12-link cart end to
#: end (``benchmarks/simulation.py --n 12``, two rounds) 2.056-2.059 → 2.073-2.075 ms at rtol
#: 5e-8, 10.8-11.0× → 10.9-11.5× PyDy.
NO_FUSED = (("-mno-fma", "-mno-fma4", "-mno-avx512f")
            if getattr(os, "uname", None) and os.uname().machine.lower() in
            ("x86_64", "amd64", "i386", "i686") else ())
#: the flags for this machine's instruction set (numeric/toolchain.py's module docstring)
NATIVE_FLAGS = ("-march=native", *NO_FUSED)

#: the lines of /proc/cpuinfo that identify a processor (not its clock, nor the core's number)
CPU_FIELDS = ("vendor_id", "cpu family", "model", "model name", "stepping", "microcode",
              "cache size", "flags", "address sizes", "CPU implementer", "CPU architecture",
              "CPU variant", "CPU part", "CPU revision", "Features")


def cpu_identity(path: str = "/proc/cpuinfo") -> str | None:
    """The identifying lines of the first processor in ``path`` (:data:`CPU_FIELDS`), or None
    where it cannot be read or names none of them."""
    keep = []
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            # up to the first blank line only: the kernel writes the file as it is read, one
            # block per processor (hundreds on a large server)
            for line in fh:
                if not line.strip():
                    break
                name, _, value = line.partition(":")
                if name.strip() in CPU_FIELDS:
                    keep.append(f"{name.strip()}={value.strip()}")
    except OSError:
        return None
    return "\n".join(keep) or None


def machine_key(cc: str, flags: tuple[str, ...] = ()) -> str | None:
    """The key of the native target of compiler ``cc`` with ``flags`` on this processor, or None
    where either cannot be identified."""
    cpu = cpu_identity()
    try:
        real = os.path.realpath(cc)
        st = os.stat(real)
    except OSError:
        return None
    if cpu is None:
        return None
    text = f"{real}\0{st.st_size}\0{st.st_mtime_ns}\0{' '.join(flags)}\0{cpu}"
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def ask_target(cc: str, flags: tuple[str, ...]) -> str | None:
    """The target options that ``flags`` (``-march=native``) expand to, as the driver of ``cc``
    reports them with ``-###``, or None when it does not know the flag."""
    try:
        r = subprocess.run([cc, *flags, "-###", "-c", "-x", "c", os.devnull, "-o",
                            os.devnull], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError):
        return None
    text = r.stdout + r.stderr
    if r.returncode != 0 or "unrecognized" in text or "unsupported" in text:
        return None
    # the expanded target options: gcc's -march=znver3 -mavx2 ... --param l1-cache-size=48,
    # clang's "-target-cpu" "znver3" "-target-feature" "+avx2" ...; not its temporary files
    words = text.replace('"', " ").split()
    keep = [w for i, w in enumerate(words)
            if w.startswith(("-m", "l1-", "l2-"))
            or (i > 0 and words[i - 1] in ("-target-cpu", "-target-feature", "-tune-cpu"))]
    return " ".join(keep) or None


def native_target_of(cc: str, flags: tuple[str, ...], folder: Path | None) -> str | None:
    """:func:`ask_target`, kept in ``folder`` (the cache; None: nowhere) under
    :func:`machine_key` as a sealed file, and read from there when kept (an answer of None is
    not kept)."""
    key = machine_key(cc, flags) if folder is not None else None
    path = folder / f"native-{key}.target" if folder is not None and key is not None else None
    if path is not None:
        data = read_sealed(path)
        if data:
            return data.decode("utf-8", errors="replace")
    target = ask_target(cc, flags)
    if path is not None and target:
        keep_sealed(path, target.encode())
    return target
