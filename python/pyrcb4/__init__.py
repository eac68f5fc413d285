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

__all__ = ["Board", "ControlLoop", "load_pose", "save_pose", "move_refusal", "Error", "BoardRefused", "Timeout", "DeviceError", "BadReply", "LimitError", "UsageError",
           "__version__"]
