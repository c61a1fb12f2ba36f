"""The first run of a model without waiting for the compiler: its generated C read as a list of
operations and evaluated by an interpreter in the integrator's library (``interpreter.h``),
while the same source compiles in a thread (issue 35: "setup in milliseconds", a fast first
path while the optimizing compiler runs in the background).

The program is read from the text that the compiler gets (:func:`program`), so that it holds
the same operations on the same operands in the same order: a sum ``(a + b + c)`` is
``(a + b) + c`` as in C, ``(-a*b)`` is ``(-a)*b``, ``jd_sq``, ``jd_powi``, ``jd_sign`` and
``jd_sincos_n`` are the header's own functions, and the solve is the generated one's. Where
both are built without contraction or reassociation (``-ffp-contract=off``, no fast-math), the
interpreter's numbers are the library's to the bit, which the tests check, so a motion does not
depend on whether its model's library was already compiled. What the reader does not know
(a construct it was not written for, a library function of a constant, which a compiler may
fold more exactly than libm computes it) makes it give up: :class:`Unreadable`, and the caller
waits for the compiler as before.

Its time per state, measured against the compiled code on the same states (M, k, q of 4 000
random states, best of 7, 2-core AMD EPYC, 2026-11-27): pendulum on a cart with 1 link
(22 operations) 0.08 against 0.02 µs, 4 links (221) 1.1 against 0.06 µs, 12 links (1 123)
5.0 against 0.18 µs, spatial chain of 4 bodies (3 776) 20 against 0.58 µs: about 5 ns per
operation, 3-35 times the compiled code, which a first short run does not notice. A long first
run does not stay on it: the C loop returns every 1 024 steps, and from the call after the
build the run takes the library's right-hand side (``_Setup.take_compiled`` in
:mod:`jourdain.simulation.problem`); later runs take the library from their start
(:func:`jourdain.numeric.first_run.run_function`).

The recursions' per-joint code (``jd_local``, split or not) is read the same way, for their
engines sized at run time (:mod:`jourdain.numeric.runtime_engine`).
"""

from __future__ import annotations

import ctypes
import re
import struct
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .functions import ContextFunction

#: operation codes (interpreter.h's JI_* in order)
(ADD, SUB, MUL, DIV, NEG, SQ, CUBE, POWI, SQRT, FN1, ATAN2, POW, FMAX, FMIN, SINCOS, STORE,
 COPY) = range(17)
#: the functions of one argument (interpreter.h's JF_* in order)
FN1_NAMES = ("sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "sinh", "cosh", "tanh",
             "asinh", "acosh", "atanh", "fabs", "jd_sign", "floor", "ceil", "erf")
_FN1 = {n: i for i, n in enumerate(FN1_NAMES)}
_FN2 = {"atan2": ATAN2, "pow": POW, "fmax": FMAX, "fmin": FMIN}
#: functions of a constant that a compiler folds exactly (the rest may differ from libm)
_EXACT_OF_CONSTANT = {"fabs", "jd_sign", "floor", "ceil", "jd_sq", "jd_cube", "jd_powi", "sqrt"}
_ARRAYS = ("y", "yd", "p", "u")

_TOKEN = re.compile(r"\s*(?:(\d+\.\d*(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+|\d+)|([A-Za-z_]\w*)"
                    r"|([-+*/(),\[\]]))")


class Unreadable(Exception):
    """The source holds something the reader was not written for (the caller compiles)."""


@dataclass
class Program:
    """Operations and registers of a generated function (see :func:`program`)."""

    f: int
    n_p: int
    n_u: int
    consts: list[float] = field(default_factory=list)
    ops: list[int] = field(default_factory=list)
    n_reg: int = 0
    n_out: int = 0
    mirror: list[int] = field(default_factory=list)
    inputs: dict[str, int] = field(default_factory=dict)


class _Reader:
    """One function's statements into a :class:`Program`. Registers: the constants first
    (their values known when they are read: numbering them in a second pass would cost a pass),
    so they are numbered apart and shifted at the end (:meth:`finish`)."""

    def __init__(self, f: int, n_p: int, n_u: int) -> None:
        self.prog = Program(f, n_p, n_u)
        self.const_of: dict[bytes, int] = {}
        self.consts: list[float] = []
        self.n_var = 0  # registers other than constants, numbered from 0 (shifted later)
        self.names: dict[str, int] = {}  # temporaries and arrays' entries -> register
        self.blocks: dict[str, int] = {}  # jd_a, jd_s, jd_c -> first register
        self.out_reg: dict[int, int] = {}
        self.ops: list[int] = []
        sizes = {"y": f, "yd": f, "p": n_p, "u": n_u}
        for arr in _ARRAYS:
            self.prog.inputs[arr] = self.n_var
            self.n_var += sizes[arr]
        self.prog.inputs["t"] = self.n_var
        self.n_var += 1
        self.sizes = sizes
        self.tokens: list[tuple[str, str, str]] = []
        self.pos = 0

    # registers: ("c", index) for constants, ("v", index) for the rest, as one int each:
    # constants negative (-1 - index) until finish()
    def const(self, v: float) -> int:
        key = struct.pack("<d", v)  # the bits: 0.0 and -0.0 are two constants
        k = self.const_of.get(key)
        if k is None:
            k = self.const_of[key] = len(self.consts)
            self.consts.append(v)
        return -1 - k

    def new(self) -> int:
        self.n_var += 1
        return self.n_var - 1

    def op(self, code: int, a: int, b: int = 0, dst: int | None = None) -> int:
        d = self.new() if dst is None else dst
        self.ops.extend((code, d, a, b))
        return d

    # ---- expressions: C's precedence, left to right ----
    def parse(self, text: str) -> int:
        self.tokens = _TOKEN.findall(text)
        if "".join("".join(t) for t in self.tokens) != re.sub(r"\s+", "", text):
            raise Unreadable(f"unknown characters in {text[:80]!r}")
        self.pos = 0
        r = self.expr()
        if self.pos != len(self.tokens):
            raise Unreadable(f"trailing text in {text[:80]!r}")
        return r

    def peek(self) -> str:
        if self.pos >= len(self.tokens):
            return ""
        n, name, punct = self.tokens[self.pos]
        return n or name or punct

    def take(self, what: str | None = None) -> str:
        tok = self.peek()
        if what is not None and tok != what:
            raise Unreadable(f"expected {what!r}, found {tok!r}")
        self.pos += 1
        return tok

    def expr(self) -> int:
        r = self.term()
        while self.peek() in ("+", "-"):
            code = ADD if self.take() == "+" else SUB
            r = self.binary(code, r, self.term())
        return r

    def term(self) -> int:
        r = self.unary()
        while self.peek() in ("*", "/"):
            code = MUL if self.take() == "*" else DIV
            r = self.binary(code, r, self.unary())
        return r

    def binary(self, code: int, a: int, b: int) -> int:
        if a < 0 and b < 0 and code == DIV:  # a quotient of two literals: exact, folded
            return self.const(self.consts[-1 - a] / self.consts[-1 - b])
        return self.op(code, a, b)

    def unary(self) -> int:
        if self.peek() == "-":
            self.take()
            a = self.unary()
            return self.const(-self.consts[-1 - a]) if a < 0 else self.op(NEG, a)
        return self.primary()

    def primary(self) -> int:
        n, name, punct = self.tokens[self.pos] if self.pos < len(self.tokens) else ("", "", "")
        if n:
            self.pos += 1
            return self.const(float(n))
        if punct == "(":
            self.take("(")
            r = self.expr()
            self.take(")")
            return r
        if not name:
            raise Unreadable(f"unexpected {punct!r}")
        self.pos += 1
        if self.peek() == "[":
            self.take("[")
            k = int(self.take())
            self.take("]")
            return self.entry(name, k)
        if self.peek() == "(":
            return self.call(name)
        if name == "t":
            return self.prog.inputs["t"]
        if name in self.names:
            return self.names[name]
        raise Unreadable(f"unknown name {name!r}")

    def entry(self, name: str, k: int) -> int:
        if name in self.sizes:
            if not 0 <= k < self.sizes[name]:
                raise Unreadable(f"{name}[{k}] out of range")
            return self.prog.inputs[name] + k
        if name == "out" and k in self.out_reg:
            return self.out_reg[k]
        if name in self.blocks:
            return self.blocks[name] + k
        if f"{name}[{k}]" in self.names:  # a split function's shared temporaries, x[k]
            return self.names[f"{name}[{k}]"]
        raise Unreadable(f"unknown array {name!r}")

    def call(self, name: str) -> int:
        self.take("(")
        args = [self.expr()]
        while self.peek() == ",":
            self.take(",")
            if name == "jd_powi":  # the exponent: an integer literal
                sign = -1 if self.peek() == "-" and self.take() else 1
                args.append(sign * int(self.take()))
                continue
            args.append(self.expr())
        self.take(")")
        if all(a < 0 for a in args[:1 if name == "jd_powi" else None]) and \
                name not in _EXACT_OF_CONSTANT:
            raise Unreadable(f"{name} of a constant")
        if name == "jd_powi" and len(args) == 2:
            return self.op(POWI, args[0], args[1])
        if len(args) == 1:
            if name in _FN1:
                return self.op(FN1, args[0], _FN1[name])
            simple = {"jd_sq": SQ, "jd_cube": CUBE, "sqrt": SQRT}
            if name in simple:
                return self.op(simple[name], args[0])
        if len(args) == 2 and name in _FN2:
            return self.op(_FN2[name], args[0], args[1])
        raise Unreadable(f"unknown function {name} of {len(args)} arguments")

    # ---- statements ----
    def statement(self, line: str) -> None:
        s = line.strip()
        if not s or s.startswith("(void)"):
            return
        if not s.endswith(";"):
            raise Unreadable(f"not a statement: {s[:80]!r}")
        s = s[:-1]
        # a split function (ccode.function_source) declares jd_a alone: its pairs go to x
        m = re.fullmatch(r"double jd_a\[(\d+)\](, jd_s\[\1\], jd_c\[\1\])?", s)
        if m:
            n = int(m.group(1))
            for name in ("jd_a", "jd_s", "jd_c")[:3 if m.group(2) else 1]:
                self.blocks[name] = self.n_var
                self.n_var += n
            return
        m = re.fullmatch(r"jd_sincos_n\(jd_a, (\d+), jd_s, jd_c\)", s)
        if m:
            if self.blocks["jd_c"] != self.blocks["jd_s"] + int(m.group(1)):
                raise Unreadable("sin/cos blocks")
            self.ops.extend((SINCOS, self.blocks["jd_s"], self.blocks["jd_a"], int(m.group(1))))
            return
        # (a split function's sin/cos pairs in x[0 … 2n), its temporaries in x[k] after them)
        m = re.fullmatch(r"jd_sincos_n\(jd_a, (\d+), x, x \+ \1\)", s)
        if m:
            n, first = int(m.group(1)), self.n_var
            self.n_var += 2 * n
            self.names.update((f"x[{k}]", first + k) for k in range(2 * n))
            self.ops.extend((SINCOS, first, self.blocks["jd_a"], n))
            return
        m = re.fullmatch(r"(x\[\d+\]) = (.*)", s)
        if m:
            self.names[m.group(1)] = self.parse(m.group(2))
            return
        m = re.fullmatch(r"const double (x\d+) = (.*)", s)
        if m:
            self.names[m.group(1)] = self.parse(m.group(2))
            return
        m = re.fullmatch(r"(jd_a|out)\[(\d+)\] = (.*)", s)
        if not m:
            raise Unreadable(f"unknown statement {s[:80]!r}")
        r, k = self.parse(m.group(3)), int(m.group(2))
        if m.group(1) == "jd_a":
            self.op(COPY, r, dst=self.blocks["jd_a"] + k)
        else:
            self.ops.extend((STORE, k, r, 0))
            self.out_reg[k] = r

    def finish(self, n_out: int, mirror: list[tuple[int, int]]) -> Program:
        """Number the constants first and the rest after them."""
        nc = len(self.consts)
        ops = np.array(self.ops, dtype=np.intc).reshape(-1, 4)
        shift = np.where(ops < 0, -1 - ops, ops + nc)
        code = ops[:, 0]
        # operand places holding registers: dst (not STORE's), a, b (binary operations)
        reg_dst = code != STORE
        reg_b = np.isin(code, (ADD, SUB, MUL, DIV, ATAN2, POW, FMAX, FMIN))
        ops[:, 1] = np.where(reg_dst, shift[:, 1], ops[:, 1])
        ops[:, 2] = shift[:, 2]
        ops[:, 3] = np.where(reg_b, shift[:, 3], ops[:, 3])
        p = self.prog
        p.consts, p.ops, p.n_reg, p.n_out = self.consts, ops.reshape(-1).tolist(), nc + self.n_var, n_out
        p.inputs = {k: v + nc for k, v in p.inputs.items()}
        p.mirror = [x for pair in mirror for x in pair]
        return p


def _body(source: str, signature: str) -> list[str]:
    """The lines of the function opened by ``signature`` in ``source``, up to its ``}``."""
    start = source.find(signature)
    if start < 0:
        raise Unreadable(f"no {signature!r}")
    open_ = source.index("{", start) + 1
    close = source.index("\n}", open_)
    return source[open_:close].splitlines()


def program(source: str, name: str, f: int, n_p: int, n_u: int, n_out: int) -> Program:
    """The program of ``NAME_upper`` in ``source`` (the generated C of
    :func:`jourdain.numeric.ccode.function_source` with ``whole`` and ``symmetric``), with
    ``NAME``'s copies into the lower triangle as its mirror pairs; :class:`Unreadable` where
    the source is not of that form."""
    reader = _Reader(f, n_p, n_u)
    try:
        for line in _body(source, f"static void {name}_upper("):
            reader.statement(line)
    except RecursionError:
        raise Unreadable("nested too deep") from None
    mirror = []
    for line in _body(source, f"\nvoid {name}("):
        s = line.strip()
        m = re.fullmatch(r"out\[(\d+)\] = out\[(\d+)\];", s)
        if m:
            mirror.append((int(m.group(1)), int(m.group(2))))
        elif s and s != f"{name}_upper(y, yd, t, p, u, out);":
            raise Unreadable(f"unknown statement {s[:80]!r}")
    return reader.finish(n_out, mirror)


class _Interp(ctypes.Structure):
    _fields_ = [(n, ctypes.c_long) for n in (
        "f", "n_p", "n_u", "n_reg", "n_const", "n_ops", "n_out", "n_mirror", "in_y", "in_yd",
        "in_t", "in_p", "in_u", "written_out")] + [
        ("consts", ctypes.c_void_p), ("ops", ctypes.c_void_p), ("mirror", ctypes.c_void_p)]


class Interpreted:
    """A :class:`Program` made ready for the interpreter: its arrays and the C structure that
    points at them (kept alive together)."""

    def __init__(self, prog: Program, written_out: bool) -> None:
        self.consts = np.array(prog.consts or [0.0], dtype=float)
        self.ops = np.array(prog.ops or [0], dtype=np.intc)
        self.mirror = np.array(prog.mirror or [0], dtype=np.int_)
        i = prog.inputs
        self.struct = _Interp(
            prog.f, prog.n_p, prog.n_u, prog.n_reg, len(prog.consts), len(prog.ops) // 4,
            prog.n_out, len(prog.mirror) // 2, i["y"], i["yd"], i["t"], i["p"], i["u"],
            int(written_out), self.consts.ctypes.data, self.ops.ctypes.data,
            self.mirror.ctypes.data)
        self.address = ctypes.addressof(self.struct)


@dataclass(frozen=True, eq=False)
class FirstFunction(ContextFunction):
    """The interface of :class:`CompiledFunction` on the interpreter: ``lib`` is the
    integrator's library, ``interp`` the program (the context of ``jd_interp_*``).
    ``compiled`` holds the compiled function once the thread that builds it is done."""

    interp: Interpreted | None = field(default=None, repr=False)

    def entries(self) -> tuple[Any, Any, Any]:
        return self.lib.jd_interp_fn, self.lib.jd_interp_batch, self.lib.jd_interp_accel

    @property
    def ctx_address(self) -> int | None:
        return None if self.interp is None else self.interp.address
