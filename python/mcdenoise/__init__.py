"""mcdenoise: denoise Monte Carlo renders on numpy arrays, through the library's C API.

    import mcdenoise, numpy as np
    out = mcdenoise.denoise(color, albedo=albedo, normal=normal)    # (H, W, C) float32
    frame = mcdenoise.read_frame("frame.exr")                       # {"color": ..., ...}
    out = mcdenoise.denoise(frame["color"], method="rhf", layers=frame, kappa=0.6)

Arrays are (height, width, channels) or (height, width), float32 or float16, of any
strides: the library reads them where they are (no copy before its own upload; a broadcast
array, of stride 0, is copied first; other real types are converted to float32). A colour
with 4 channels is RGB and alpha; the result's fourth channel is that alpha, except that a
pixel of alpha 0 beside covered ones takes the alpha_rim share (0.02) of their colour and
alpha alike (the renderer's pixel filter past an edge; alpha_rim=0 keeps the alpha as it
is). A 3-channel colour with an "alpha" layer returns 3 channels: the alpha does not come
back, so no light moves into pixels of alpha 0 (they keep the input's colour). Failures raise
mcdenoise.Error subclasses (one per error code) with the library's message; the library's
warnings are Python warnings (mcdenoise.LibraryWarning).
"""

import ctypes
import math
import warnings

import numpy as np

from . import _capi
from ._capi import View

__all__ = ["denoise", "read_frame", "write_exr", "methods", "method_params", "version",
           "Device", "Error", "InvalidArgumentError", "MissingLayerError",
           "NonFiniteInputError", "OutOfMemoryError", "DeviceError", "IoError",
           "InternalError", "CancelledError", "LibraryWarning"]


class Error(Exception):
    """A failure the library reported; `code` is its MCDError code."""
    code = None


class InvalidArgumentError(Error, ValueError):
    code = 1


class MissingLayerError(Error, LookupError):
    code = 2


class NonFiniteInputError(Error, ValueError):
    code = 3


class OutOfMemoryError(Error, MemoryError):
    code = 4


class DeviceError(Error, RuntimeError):
    code = 5


class IoError(Error, OSError):
    code = 6


class InternalError(Error, RuntimeError):
    code = 7


class CancelledError(Error):
    code = 8


class LibraryWarning(UserWarning):
    """A warning of a run (e.g. NaN/Inf input values replaced by 0)."""


_ERRORS = {cls.code: cls for cls in (InvalidArgumentError, MissingLayerError,
                                     NonFiniteInputError, OutOfMemoryError, DeviceError,
                                     IoError, InternalError, CancelledError)}


def _check(ok):
    """Raise the thread's library error when a call failed (returned NULL/0/False)."""
    message = ctypes.c_char_p()
    code = _capi.core.mcdGetError(ctypes.byref(message))
    if code:
        raise _ERRORS.get(code, Error)(message.value.decode(errors="replace"))
    if ok is None or ok is False:
        raise InternalError("the library failed without an error")
    return ok


def _text(value):
    return value.decode(errors="replace") if value is not None else None


def version():
    return _text(_capi.core.mcdVersion())


def methods():
    """The method names: "auto" first."""
    core = _capi.core
    return [_text(core.mcdGetMethodName(i)) for i in range(core.mcdGetMethodCount())]


class _Method:
    def __init__(self, name):
        if not isinstance(name, str):
            raise InvalidArgumentError(f"method: {name!r} is not a method's name (a str)")
        self.handle = _check(_capi.core.mcdNewMethod(name.encode()))

    def __del__(self):
        if getattr(self, "handle", None):
            _capi.core.mcdReleaseMethod(self.handle)

    def set(self, name, value):
        core, key = _capi.core, name.replace("_", "-").encode()
        if isinstance(value, (bool, np.bool_)):
            ok = core.mcdSetMethodBool(self.handle, key, bool(value))
        elif isinstance(value, (int, np.integer)) and -2**31 <= int(value) < 2**31:
            ok = core.mcdSetMethodInt(self.handle, key, int(value))
        elif isinstance(value, (int, np.integer)):  # beyond a C int: the range check says so
            big = int(value)
            ok = core.mcdSetMethodFloat(self.handle, key, float(big) if abs(big) < 2**1000
                                        else math.copysign(math.inf, big))
        elif isinstance(value, (float, np.floating)):
            ok = core.mcdSetMethodFloat(self.handle, key, float(value))
        elif isinstance(value, str):
            ok = core.mcdSetMethodString(self.handle, key, value.encode())
        else:
            raise InvalidArgumentError(f"parameter '{name}': {type(value).__name__} is not "
                                       "a bool, int, float or str")
        _check(ok)


def method_params(method="auto"):
    """The method's parameters with their defaults, as text ({"kappa": "0.6", ...})."""
    m, core = _Method(method), _capi.core
    names = [core.mcdGetMethodParamName(m.handle, i)
             for i in range(core.mcdGetMethodParamCount(m.handle))]
    return {_text(n): _text(_check(core.mcdGetMethodParamText(m.handle, n))) for n in names}


class Device:
    """A Vulkan device: `name` an index or a name substring; None: $MCD_DEVICE, then the
    best. Its kernels are built on first use and kept, so keep one for many calls."""

    def __init__(self, name=None):
        self.handle = _check(_capi.core.mcdNewDevice(
            str(name).encode() if name is not None else None))
        self.name = _text(_capi.core.mcdGetDeviceName(self.handle))

    def __del__(self):
        if getattr(self, "handle", None):
            _capi.core.mcdReleaseDevice(self.handle)


_default_device = None


def _device(device):
    global _default_device
    if isinstance(device, (bool, np.bool_)):
        raise InvalidArgumentError("device: a bool is not a Device, a name or an index")
    if isinstance(device, (str, int, np.integer)):  # as Device(name) takes it
        return Device(device if isinstance(device, str) else int(device))
    if device is not None and not isinstance(device, Device):
        raise InvalidArgumentError(f"device: {type(device).__name__} is not a Device, a "
                                   "name or an index")
    if device is not None:
        return device
    if _default_device is None:
        _default_device = Device()
    return _default_device


def _layer_array(array, name):
    """`array` as a (height, width, channels) float32 or float16 array, without a copy
    when it is one already (any strides but a broadcast's 0)."""
    array = np.asarray(array)
    if array.dtype.kind not in "fiub":  # complex, text, objects: no image
        raise InvalidArgumentError(f"layer '{name}': an array of {array.dtype}; expected "
                                   "float32 or float16 (or real numbers to convert)")
    if array.dtype not in (np.float32, np.float16):
        array = array.astype(np.float32)
    if array.ndim == 2:
        array = array[:, :, np.newaxis]
    if array.ndim != 3:
        raise InvalidArgumentError(f"layer '{name}': an array of shape {array.shape}; "
                                   "expected (height, width) or (height, width, channels)")
    # A stride of 0 (a broadcast) means "packed" to the C views: such an array is copied.
    if any(stride == 0 and size > 1 for stride, size in zip(array.strides, array.shape)):
        array = np.ascontiguousarray(array)
    return array


def _view(array):
    """The C view of a (height, width, channels) array, strides as they are."""
    height, width, channels = array.shape
    rows, pixels, chans = array.strides
    return View(array.ctypes.data, _capi.FORMAT_HALF if array.dtype == np.float16
                else _capi.FORMAT_FLOAT, width, height, channels, pixels, rows, chans)


class _Frame:
    def __init__(self, handle=None):
        self.handle = handle or _check(_capi.core.mcdNewFrame())
        self.arrays = []  # what the frame borrows, alive as long as it is

    def __del__(self):
        if getattr(self, "handle", None):
            _capi.core.mcdReleaseFrame(self.handle)

    def set(self, name, array):
        if not isinstance(name, str):
            raise InvalidArgumentError(f"layer name {name!r} is not a str")
        array = _layer_array(array, name)
        self.arrays.append(array)
        view = _view(array)
        _check(_capi.core.mcdSetFrameLayer(self.handle, name.encode(), ctypes.byref(view)))


def _progress_function(progress, failures):
    def call(user, stage, done, total):
        try:
            return progress(_text(stage), done, total) is not False
        except BaseException as e:  # not across the C frames: re-raised after the run
            failures.append(e)
            return False
    return _capi.PROGRESS(call)


def denoise(color, method="auto", albedo=None, normal=None, depth=None, variance=None, *,
            layers=None, device=None, progress=None, **params):
    """Denoise `color` ((height, width, channels) or (height, width), float32 or float16)
    with `method` ("auto" or one of methods()) and return an array of its shape and type.

    albedo, normal, depth, variance: the frame's layers of those names; `layers`: any
    others by the library's names (e.g. read_frame's dict: hist, min, max, spp, ...), the
    named arguments taking precedence. params: the method's parameters by their command
    line names, "-" written "_" (kappa=0.6, non_finite="zero"). progress(stage, done,
    total): called as the run advances; returning False cancels it (CancelledError).
    device: a Device (its pipelines kept across calls), a name or an index (a device opened
    for this call), or None (the default device, kept). An RGBA `color` returns RGBA, the alpha with alpha_rim's shares moved; a 3-channel one
    returns 3 channels and runs without alpha_rim (its alpha would not come back).
    """
    flat = np.ndim(color) == 2
    color = _layer_array(color, "color")
    given = dict(layers or {})
    given.update({k: v for k, v in (("albedo", albedo), ("normal", normal),
                                    ("depth", depth), ("variance", variance)) if v is not None})
    given.pop("color", None)
    rgba = color.shape[2] == 4
    # RGB and alpha: the result's alpha (alpha_rim's shares moved) is its fourth channel
    if rgba:
        given["alpha"] = color[:, :, 3:]
        color = color[:, :, :3]
    frame = _Frame()
    frame.set("color", color)
    for name, array in given.items():
        frame.set(name, array)

    m = _Method(method)
    for name, value in params.items():
        m.set(name, value)
    failures = []
    callback = _progress_function(progress, failures) if progress else None
    if callback:
        _capi.core.mcdSetMethodProgressFunction(m.handle, callback, None)

    out = np.empty(color.shape[:2] + (color.shape[2] + rgba,), color.dtype)
    view = _view(out)
    dev = _device(device)  # held through the run: one made here from a name is released after
    result = _capi.core.mcdRunMethod(m.handle, dev.handle, frame.handle, ctypes.byref(view))
    if failures:  # the progress function raised: the run was cancelled for it
        _capi.core.mcdReleaseResult(result)
        _capi.core.mcdGetError(None)
        raise failures[0]
    _check(result)
    core = _capi.core
    try:
        for i in range(core.mcdGetResultWarningCount(result)):
            warnings.warn(_text(core.mcdGetResultWarning(result, i)), LibraryWarning,
                          stacklevel=2)
    finally:
        core.mcdReleaseResult(result)
    return out[:, :, 0] if flat else out


def read_frame(path, layers=None):
    """Read an image file (EXR, PFM, HDR, PNG, ...) into {layer name: (height, width,
    channels) float32 array}, the layers grouped and named as the library reads them
    (color, albedo, normal, variance, hist, ...); `layers` names the ones to read ("partial*":
    every partial image there is). A layer named there and absent raises MissingLayerError."""
    core, names = _capi.core, None
    if layers is not None:
        layers = [layers] if isinstance(layers, str) else list(layers)
        for n in layers:
            if not isinstance(n, str):
                raise InvalidArgumentError(f"layer name {n!r} is not a str")
        names = (ctypes.c_char_p * len(layers))(*[n.encode() for n in layers])
    handle = _check(_capi.io.mcdReadFrame(str(path).encode(), names,
                                          len(layers) if layers is not None else 0))
    frame = _Frame(handle)
    height, width = core.mcdGetFrameHeight(handle), core.mcdGetFrameWidth(handle)
    result = {}
    for i in range(core.mcdGetFrameLayerCount(handle)):
        name = core.mcdGetFrameLayerName(handle, i)
        array = np.empty((height, width, core.mcdGetFrameLayerChannels(handle, name)),
                         np.float32)
        view = _view(array)
        _check(core.mcdCopyFrameLayer(frame.handle, name, ctypes.byref(view)))
        result[_text(name)] = array
    lacking = [n for n in layers or [] if n not in result and not n.endswith("*")]
    if lacking:
        raise MissingLayerError(f"{path} has no layer {', '.join(map(repr, lacking))}")
    return result


def write_exr(path, layers):
    """Write {layer name: array} as a float32 EXR (zip), atomically; read_frame reads the
    same layers back."""
    arrays = [(name, _layer_array(array, name)) for name, array in layers.items()]
    names = (ctypes.c_char_p * len(arrays))(*[n.encode() for n, _ in arrays])
    views = (View * len(arrays))(*[_view(a) for _, a in arrays])
    _check(_capi.io.mcdWriteExr(str(path).encode(), names, views, len(arrays)))
