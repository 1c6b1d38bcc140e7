"""OSMesa (Mesa's off-screen GL, Debian package libosmesa6) as a moderngl context loader.

glcontext has no OSMesa backend, but moderngl 5.13 accepts any loader object:
`moderngl.create_context(standalone=True, context=loader)` calls
`loader.load_opengl_function(name) -> int` for every GL entry point and `loader.release()`
when the context is released. `OSMesaLoader` is that object, written with ctypes:

1. `OSMesaCreateContextAttribs` with a core profile of at least 3.3 (Mesa answers with the
   highest core version it has: 4.5 on llvmpipe). OSMesa has no depth or stencil buffer of
   its own here (we render into framebuffer objects).
2. `OSMesaMakeCurrent` on a 1x1 RGBA8 buffer that the loader keeps alive: OSMesa needs some
   buffer to be current, and nothing is ever drawn into it.
3. `OSMesaGetProcAddress` answers `load_opengl_function`.
4. `release()` unbinds the context if it is current, then destroys it; calling it twice is
   harmless, so several contexts can be made and released one after another in one process.

EGL and OSMesa share Mesa's GL dispatch in one process, so switching between an OSMesa and
an EGL context needs an explicit make-current on each side: renderer/gpu/context.py does that.
"""

from __future__ import annotations

import ctypes
import ctypes.util

# OSMesa attribute names and values (GL/osmesa.h).
OSMESA_FORMAT = 0x22
OSMESA_RGBA = 0x1908                 # = GL_RGBA
OSMESA_DEPTH_BITS = 0x30
OSMESA_STENCIL_BITS = 0x31
OSMESA_ACCUM_BITS = 0x32
OSMESA_PROFILE = 0x33
OSMESA_CORE_PROFILE = 0x34
OSMESA_CONTEXT_MAJOR_VERSION = 0x36
OSMESA_CONTEXT_MINOR_VERSION = 0x37
GL_UNSIGNED_BYTE = 0x1401

LIBRARY_NAMES = ("libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so")
REQUIRED_VERSION = (3, 3)            # core profile; Mesa gives its highest core version
_BUFFER_SIZE = 1                     # pixels per side of the (never drawn) OSMesa buffer

_library: ctypes.CDLL | None = None


class OSMesaError(RuntimeError):
    """libOSMesa is missing or refused to make a context (one line, for ContextError)."""


def load_library() -> ctypes.CDLL:
    """libOSMesa with the prototypes we call, loaded once per process."""
    global _library
    if _library is not None:
        return _library
    names = list(LIBRARY_NAMES)
    found = ctypes.util.find_library("OSMesa")
    if found and found not in names:
        names.append(found)
    errors = []
    for name in names:
        try:
            lib = ctypes.CDLL(name)
        except OSError as exc:
            errors.append(str(exc))
            continue
        if not hasattr(lib, "OSMesaCreateContextAttribs"):
            errors.append(f"{name} has no OSMesaCreateContextAttribs (too old for a core profile)")
            continue
        _declare(lib)
        _library = lib
        return lib
    raise OSMesaError("cannot load libOSMesa (" + "; ".join(errors) + ")")


def _declare(lib: ctypes.CDLL) -> None:
    lib.OSMesaCreateContextAttribs.restype = ctypes.c_void_p
    lib.OSMesaCreateContextAttribs.argtypes = [ctypes.POINTER(ctypes.c_int), ctypes.c_void_p]
    lib.OSMesaMakeCurrent.restype = ctypes.c_ubyte
    lib.OSMesaMakeCurrent.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint,
                                      ctypes.c_int, ctypes.c_int]
    lib.OSMesaGetCurrentContext.restype = ctypes.c_void_p
    lib.OSMesaGetCurrentContext.argtypes = []
    lib.OSMesaGetProcAddress.restype = ctypes.c_void_p
    lib.OSMesaGetProcAddress.argtypes = [ctypes.c_char_p]
    lib.OSMesaDestroyContext.restype = None
    lib.OSMesaDestroyContext.argtypes = [ctypes.c_void_p]


class OSMesaLoader:
    """One OSMesa core-profile context, in the shape moderngl's `context=` argument expects."""

    def __init__(self, version: tuple[int, int] = REQUIRED_VERSION):
        self._lib = load_library()
        attributes = [
            OSMESA_FORMAT, OSMESA_RGBA,
            OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0, OSMESA_ACCUM_BITS, 0,
            OSMESA_PROFILE, OSMESA_CORE_PROFILE,
            OSMESA_CONTEXT_MAJOR_VERSION, version[0],
            OSMESA_CONTEXT_MINOR_VERSION, version[1],
            0,
        ]
        self._attributes = (ctypes.c_int * len(attributes))(*attributes)
        self._handle = self._lib.OSMesaCreateContextAttribs(self._attributes, None)
        if not self._handle:
            raise OSMesaError(f"OSMesaCreateContextAttribs refused a core {version[0]}.{version[1]} "
                              "profile context")
        # The buffer must outlive the binding: OSMesa keeps a pointer to it.
        self._buffer = ctypes.create_string_buffer(_BUFFER_SIZE * _BUFFER_SIZE * 4)
        if not self.make_current():
            self.release()
            raise OSMesaError("OSMesaMakeCurrent failed")

    @property
    def handle(self) -> int | None:
        """The OSMesaContext pointer (None once released)."""
        return self._handle

    def make_current(self) -> bool:
        if not self._handle:
            return False
        return bool(self._lib.OSMesaMakeCurrent(self._handle, self._buffer, GL_UNSIGNED_BYTE,
                                                _BUFFER_SIZE, _BUFFER_SIZE))

    def is_current(self) -> bool:
        return bool(self._handle) and self._lib.OSMesaGetCurrentContext() == self._handle

    def get_proc_address(self, name: str) -> int:
        return self._lib.OSMesaGetProcAddress(name.encode("ascii")) or 0

    # -- the moderngl loader protocol -------------------------------------------------------
    def load_opengl_function(self, name: str) -> int:
        return self.get_proc_address(name)

    def release(self) -> None:
        if not self._handle:
            return
        if self.is_current():
            self._lib.OSMesaMakeCurrent(None, None, 0, 0, 0)     # unbind before destroying
        self._lib.OSMesaDestroyContext(self._handle)
        self._handle = None

    def __enter__(self):
        self.make_current()
        return self

    def __exit__(self, *exc) -> None:
        pass
