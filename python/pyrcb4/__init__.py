"""rcb4 for Python: KONDO's RCB-4 robot controller (KHR-3HV, KXR) over its serial line.

    import pyrcb4
    with pyrcb4.Board() as b:            # None: an in-process virtual board; or "/dev/ttyUSB0"
        print(b.joints()["left_knee"])
        b.move({"left_knee": 40}, time=0.8)

One ICS servo on its own line (a KONDO adapter in ICS mode), as `rcb4 ics` sets one up:

    with pyrcb4.IcsServo() as s:         # None: an in-process virtual servo; or "/dev/ttyUSB0"
        s.set(stretch=40, speed=100)     # the old EEPROM image saved first (ics-idN-STAMP.bin)
        s.move(degrees=30)

The work is done by rcb4's C++ library (the _core extension); every failure is a pyrcb4.Error.
"""
from ._core import (  # noqa: F401
    BadReply,
    Board,
    BoardRefused,
    ControlLoop,
    DeviceError,
    Error,
    IcsServo,
    LimitError,
    Timeout,
    UsageError,
    __version__,
    ics_scan,
    load_pose,
    move_refusal,
    save_pose,
)



class ArgumentError(UsageError, TypeError):
    """An argument of the wrong type (a UsageError, and a TypeError as Python raises for one)."""


def _one_line(name, method, cls="Board", bound=True):
    """method (of pyrcb4.cls; bound=False: a module function), with pybind11's many-line
    "incompatible function arguments" TypeError as one line."""
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
                    takes = takes.replace(f"self: pyrcb4._core.{cls}, ", "").replace(f"self: pyrcb4._core.{cls}", "")
                    takes = takes.replace("*args", "*names")
            passed = args[1:] if bound else args
            given = repr(tuple(passed)) if not kwargs else \
                "(" + ", ".join([repr(a) for a in passed] + [f"{k}={v!r}" for k, v in kwargs.items()]) + ")"
            raise ArgumentError(f"{name}{takes or '(...)'}: called with {given}") from None
    return call


for _cls in (Board, IcsServo):
    for _name, _member in list(vars(_cls).items()):
        if _name == "__init__" or (not _name.startswith("_") and callable(_member)):
            setattr(_cls, _name, _one_line(_cls.__name__ if _name == "__init__" else _name, _member, _cls.__name__))
ics_scan = _one_line("ics_scan", ics_scan, bound=False)
del _cls, _name, _member

__all__ = ["Board", "IcsServo", "ics_scan", "ArgumentError", "ControlLoop", "load_pose", "save_pose", "move_refusal", "Error", "BoardRefused", "Timeout", "DeviceError", "BadReply", "LimitError", "UsageError",
           "__version__"]
