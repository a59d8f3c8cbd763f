"""ctypes declarations of mcdenoise's C API (include/mcdenoise/mcdenoise_c.h, io_c.h)."""

import ctypes
import os

c_int, c_bool, c_double, c_char_p, c_void_p = (
    ctypes.c_int, ctypes.c_bool, ctypes.c_double, ctypes.c_char_p, ctypes.c_void_p)

FORMAT_FLOAT, FORMAT_HALF = 1, 2


class View(ctypes.Structure):
    _fields_ = [("data", c_void_p), ("format", c_int), ("width", c_int), ("height", c_int),
                ("channels", c_int), ("pixelByteStride", ctypes.c_int64),
                ("rowByteStride", ctypes.c_int64), ("channelByteStride", ctypes.c_int64)]


PROGRESS = ctypes.CFUNCTYPE(c_bool, c_void_p, c_char_p, c_int, c_int)

# name: (result type, argument types)
_CORE = {
    "mcdGetError": (c_int, [ctypes.POINTER(c_char_p)]),
    "mcdErrorName": (c_char_p, [c_int]),
    "mcdVersion": (c_char_p, []),
    "mcdNewDevice": (c_void_p, [c_char_p]),
    "mcdReleaseDevice": (None, [c_void_p]),
    "mcdGetDeviceName": (c_char_p, [c_void_p]),
    "mcdNewFrame": (c_void_p, []),
    "mcdReleaseFrame": (None, [c_void_p]),
    "mcdSetFrameLayer": (c_bool, [c_void_p, c_char_p, ctypes.POINTER(View)]),
    "mcdGetFrameWidth": (c_int, [c_void_p]),
    "mcdGetFrameHeight": (c_int, [c_void_p]),
    "mcdGetFrameLayerCount": (c_int, [c_void_p]),
    "mcdGetFrameLayerName": (c_char_p, [c_void_p, c_int]),
    "mcdGetFrameLayerChannels": (c_int, [c_void_p, c_char_p]),
    "mcdCopyFrameLayer": (c_bool, [c_void_p, c_char_p, ctypes.POINTER(View)]),
    "mcdGetMethodCount": (c_int, []),
    "mcdGetMethodName": (c_char_p, [c_int]),
    "mcdNewMethod": (c_void_p, [c_char_p]),
    "mcdReleaseMethod": (None, [c_void_p]),
    "mcdGetMethodSummary": (c_char_p, [c_void_p]),
    "mcdSetMethodBool": (c_bool, [c_void_p, c_char_p, c_bool]),
    "mcdSetMethodInt": (c_bool, [c_void_p, c_char_p, c_int]),
    "mcdSetMethodFloat": (c_bool, [c_void_p, c_char_p, c_double]),
    "mcdSetMethodString": (c_bool, [c_void_p, c_char_p, c_char_p]),
    "mcdSetMethodText": (c_bool, [c_void_p, c_char_p, c_char_p]),
    "mcdGetMethodParamCount": (c_int, [c_void_p]),
    "mcdGetMethodParamName": (c_char_p, [c_void_p, c_int]),
    "mcdGetMethodParamText": (c_char_p, [c_void_p, c_char_p]),
    "mcdSetMethodProgressFunction": (None, [c_void_p, PROGRESS, c_void_p]),
    "mcdRunMethod": (c_void_p, [c_void_p, c_void_p, c_void_p, ctypes.POINTER(View)]),
    "mcdReleaseResult": (None, [c_void_p]),
    "mcdGetResultMethod": (c_char_p, [c_void_p]),
    "mcdGetResultCandidateCount": (c_int, [c_void_p]),
    "mcdGetResultCandidate": (c_char_p, [c_void_p, c_int]),
    "mcdGetResultPlanCount": (c_int, [c_void_p]),
    "mcdGetResultPlanLine": (c_char_p, [c_void_p, c_int]),
    "mcdGetResultWarningCount": (c_int, [c_void_p]),
    "mcdGetResultWarning": (c_char_p, [c_void_p, c_int]),
    "mcdGetResultWallMs": (c_double, [c_void_p]),
    "mcdGetResultGpuMs": (c_double, [c_void_p]),
}
_IO = {
    "mcdReadFrame": (c_void_p, [c_char_p, ctypes.POINTER(c_char_p), c_int]),
    "mcdWriteExr": (c_bool, [c_char_p, ctypes.POINTER(c_char_p), ctypes.POINTER(View), c_int]),
}


def _library_dir():
    """Where the shared libraries are: $MCDENOISE_LIBRARY_DIR, else where the install put
    them beside this package (_location.py, written by CMake), else the loader's path."""
    if os.environ.get("MCDENOISE_LIBRARY_DIR"):
        return os.environ["MCDENOISE_LIBRARY_DIR"]
    try:
        from . import _location
    except ImportError:
        return None
    return os.path.normpath(os.path.join(os.path.dirname(__file__), _location.LIBRARY_DIR))


def _load(soname, functions):
    directory = _library_dir()
    path = os.path.join(directory, soname) if directory else soname
    try:
        library = ctypes.CDLL(path)
    except OSError as e:
        raise ImportError(f"mcdenoise: cannot load {path} ({e}); set MCDENOISE_LIBRARY_DIR "
                          "to the directory of the installed libmcdenoise") from e
    for name, (restype, argtypes) in functions.items():
        function = getattr(library, name)
        function.restype, function.argtypes = restype, argtypes
    return library


core = _load("libmcdenoise.so.0", _CORE)
io = _load("libmcdenoise_io.so.0", _IO)
