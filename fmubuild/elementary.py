"""Which elementary functions an FMU computes with: the C library's (``libm``, the default: the
fastest on each host, last-place differences between hosts) or the FMUs' own (``own``:
``runtime/elementary.h``, the same bits on every host). With ``own``, the generated C and the
integrator call ``rcm_exp`` for ``exp`` and so on (outside comments) and include ``elementary.h``
after ``math.h``."""

from __future__ import annotations

import re

#: --elementary: the C library's functions, or runtime/elementary.h's.
CHOICES = ("libm", "own")
DEFAULT = "libm"
HEADER = "elementary.h"
#: The C library's functions that runtime/elementary.h implements (its ``rcm_`` names).
OWN_FUNCTIONS = ("exp", "log", "pow", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "tanh")
#: The runtime's C files that call elementary functions (the integrator's step-size factor).
RUNTIME_CALLERS = ("ode23s.c",)

_CALL = re.compile(r"(?<![\w.])(" + "|".join(OWN_FUNCTIONS) + r")\s*\(")


def _is_code(line: str) -> bool:
    """A line of C that is neither a comment line (CasADi's ``/* ... */``) nor a preprocessor line."""
    return not line.lstrip().startswith(("/*", "*", "//", "#"))


def check(choice: str) -> str:
    """``choice`` if it is one of CHOICES, else ValueError naming the allowed ones."""
    if choice not in CHOICES:
        raise ValueError(f"--elementary {choice!r}: expected one of {', '.join(CHOICES)}")
    return choice


def use_own_elementary(code: str) -> str:
    """C ``code`` calling elementary.h's functions instead of the C library's; comment lines and
    preprocessor lines are left as they are."""
    lines = []
    for line in code.splitlines(keepends=True):
        lines.append(_CALL.sub(r"rcm_\1(", line) if _is_code(line) else line)
    text = "".join(lines)
    if "#include <math.h>\n" not in text:
        raise ValueError("C without #include <math.h>: cannot place elementary.h after it")
    return text.replace("#include <math.h>\n", f'#include <math.h>\n#include "{HEADER}"\n', 1)


def remaining_calls(code: str) -> list[str]:
    """The C library's elementary functions ``code`` still calls outside comments (for checks)."""
    return [name for line in code.splitlines() if _is_code(line) for name in _CALL.findall(line)]
