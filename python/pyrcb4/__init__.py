"""rcb4 for Python: KONDO's RCB-4 robot controller (KHR-3HV, KXR) over its serial line.

    import pyrcb4
    with pyrcb4.Board() as b:            # None: an in-process virtual board; or "/dev/ttyUSB0"
        print(b.joints()["left_knee"])
        b.move({"left_knee": 40}, time=0.8)

The work is done by rcb4's C++ library (the _core extension); every failure is a pyrcb4.Error.
"""
from ._core import (  # noqa: F401
    BadReply,
    Board,
    BoardRefused,
    ControlLoop,
    DeviceError,
    Error,
    LimitError,
    Timeout,
    UsageError,
    __version__,
    load_pose,
    move_refusal,
    save_pose,
)



class ArgumentError(UsageError, TypeError):
    """An argument of the wrong type (a UsageError, and a TypeError as Python raises for one)."""


def _one_line(name, method):
    """method, with pybind11's many-line "incompatible function arguments" TypeError as one line."""
    import functools

    @functools.wraps(method)
    def call(*args, **kwargs):
        try:
            return method(*args, **kwargs)
        except TypeError as e:
            text = str(e)
            if "incompatible function arguments" not in text and "incompatible constructor arguments" not in text:
                raise
            # "1. (self: pyrcb4._core.Board, n: int, ...) -> object" names what it takes.
            takes = ""
            for line in text.splitlines():
                if line.strip().startswith("1. ("):
                    takes = line.strip()[3:].split(") -> ")[0] + ")"
                    takes = takes.replace("self: pyrcb4._core.Board, ", "").replace("self: pyrcb4._core.Board", "")
                    takes = takes.replace("*args", "*names")
            given = repr(tuple(args[1:])) if not kwargs else \
                "(" + ", ".join([repr(a) for a in args[1:]] + [f"{k}={v!r}" for k, v in kwargs.items()]) + ")"
            raise ArgumentError(f"{name}{takes or '(...)'}: called with {given}") from None
    return call


for _name, _member in list(vars(Board).items()):
    if _name == "__init__" or (not _name.startswith("_") and callable(_member)):
        setattr(Board, _name, _one_line("Board" if _name == "__init__" else _name, _member))
del _name, _member

__all__ = ["Board", "ArgumentError", "ControlLoop", "load_pose", "save_pose", "move_refusal", "Error", "BoardRefused", "Timeout", "DeviceError", "BadReply", "LimitError", "UsageError",
           "__version__"]
