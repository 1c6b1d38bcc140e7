"""Headless OpenGL contexts for moderngl: EGL (glcontext) or OSMesa (renderer/gpu/osmesa.py).

    ctx = make_context("auto")        # EGL if it starts, else OSMesa; ContextError if neither
    context_kind(ctx)                 # "egl", "osmesa", "window" (adopt_context), or "external"
    activate(ctx)                     # make ctx current before drawing with it
    release_context(ctx)

Both kinds are Mesa's llvmpipe on this machine and share Mesa's GL dispatch inside one
process: making an OSMesa context current silently redirects the GL calls of an EGL context
that libglvnd still believes is current. `activate()` therefore re-binds our EGL contexts
with a release-then-bind pair of `eglMakeCurrent` calls (about 3 µs) and our OSMesa contexts
with `OSMesaMakeCurrent` when they are not current. A context made elsewhere (passed in by a
caller) is assumed to be current already.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import subprocess
import sys
import weakref

import moderngl

from renderer.errors import ContextError
from renderer.gpu.osmesa import OSMesaLoader

KINDS = ("auto", "egl", "osmesa")
REQUIRED_GL = 330                    # moderngl's version code: OpenGL 3.3 core at least
PACKAGES = {                         # Debian packages that provide each kind
    "egl": "libegl1 libegl-mesa0 libgl1-mesa-dri libgl1",
    "osmesa": "libosmesa6",
}

_EGL_DRAW, _EGL_READ = 0x3059, 0x305A


class _EglBinding:
    """Handles of an EGL context captured while glcontext had just made it current."""
    kind = "egl"

    def __init__(self):
        self._egl = _load_egl()
        self.display = self._egl.eglGetCurrentDisplay()
        self.context = self._egl.eglGetCurrentContext()
        self.draw = self._egl.eglGetCurrentSurface(_EGL_DRAW)
        self.read = self._egl.eglGetCurrentSurface(_EGL_READ)
        if not self.context:
            raise RuntimeError("glcontext made an EGL context that is not current")

    def make_current(self) -> None:
        _release_window()
        # Unbind first: libglvnd skips a make-current of the context it thinks is current,
        # which would leave Mesa's dispatch pointing at an OSMesa context.
        self._egl.eglMakeCurrent(self.display, None, None, None)
        if not self._egl.eglMakeCurrent(self.display, self.draw, self.read, self.context):
            raise ContextError("eglMakeCurrent failed for the renderer's EGL context")

    def needs_binding(self) -> bool:
        return True

    def get_proc_address(self, name: str) -> int:
        return self._egl.eglGetProcAddress(name.encode("ascii")) or 0

    def after_release(self) -> None:
        # glcontext destroyed the context; EGL frees it only once it is no longer current.
        self._egl.eglMakeCurrent(self.display, None, None, None)


class _OSMesaBinding:
    kind = "osmesa"

    def __init__(self, loader: OSMesaLoader):
        self.loader = loader

    def make_current(self) -> None:
        _release_window()
        if not self.loader.make_current():
            raise ContextError("OSMesaMakeCurrent failed for the renderer's OSMesa context")

    def needs_binding(self) -> bool:
        return not self.loader.is_current()

    def get_proc_address(self, name: str) -> int:
        return self.loader.get_proc_address(name)

    def after_release(self) -> None:
        pass                              # the loader's release() unbound and destroyed it


class _WindowBinding:
    """A context a window library made (renderer/viewer/window.py: glfw, so GLX here), adopted so
    that activate() and gl_function() treat it like ours.

    libglvnd lets one thread have a current context of one API only: an EGL context cannot
    be made current while a GLX one is (eglMakeCurrent fails), nor the reverse. So binding
    this context first releases any current EGL context, and binding or making one of ours
    first releases this one (_release_window). glfw's own record of the current context
    does not see EGL or OSMesa take over, so every activate() binds again, release first,
    as for EGL."""
    kind = "window"

    def __init__(self, make_current, release, get_proc_address):
        self._make_current, self._release = make_current, release
        self._get_proc_address = get_proc_address

    def make_current(self) -> None:
        global _current_window
        _release_egl()
        self._release()
        self._make_current()
        _current_window = self

    def release_current(self) -> None:
        global _current_window
        self._release()
        _current_window = None

    def needs_binding(self) -> bool:
        return True

    def get_proc_address(self, name: str) -> int:
        return self._get_proc_address(name) or 0

    def after_release(self) -> None:
        self.release_current()            # the window library destroys it with the window


_current_window: _WindowBinding | None = None


def _release_window() -> None:
    """Before an EGL or OSMesa context is made or bound: release a current window context."""
    if _current_window is not None:
        _current_window.release_current()


def _release_egl() -> None:
    """Before a window context is bound: release a current EGL context, if EGL is loaded."""
    if _egl_library is not None:
        display = _egl_library.eglGetCurrentDisplay()
        if display:
            _egl_library.eglMakeCurrent(display, None, None, None)


_bindings: "weakref.WeakKeyDictionary[moderngl.Context, object]" = weakref.WeakKeyDictionary()
_egl_library: ctypes.CDLL | None = None


def _load_egl() -> ctypes.CDLL:
    global _egl_library
    if _egl_library is None:
        lib = ctypes.CDLL(ctypes.util.find_library("EGL") or "libEGL.so.1")
        for name in ("eglGetCurrentDisplay", "eglGetCurrentContext", "eglGetProcAddress"):
            getattr(lib, name).restype = ctypes.c_void_p
        lib.eglGetCurrentDisplay.argtypes = lib.eglGetCurrentContext.argtypes = []
        lib.eglGetProcAddress.argtypes = [ctypes.c_char_p]
        lib.eglGetCurrentSurface.restype = ctypes.c_void_p
        lib.eglGetCurrentSurface.argtypes = [ctypes.c_int]
        lib.eglMakeCurrent.restype = ctypes.c_uint
        lib.eglMakeCurrent.argtypes = [ctypes.c_void_p] * 4
        _egl_library = lib
    return _egl_library


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


def _make_egl() -> moderngl.Context:
    _release_window()
    ctx = moderngl.create_standalone_context(require=REQUIRED_GL, backend="egl")
    try:
        _bindings[ctx] = _EglBinding()
    except Exception:
        ctx.release()
        raise
    return ctx


def _make_osmesa() -> moderngl.Context:
    _release_window()
    loader = OSMesaLoader()
    try:
        ctx = moderngl.create_context(require=REQUIRED_GL, standalone=True, context=loader)
    except Exception:
        loader.release()
        raise
    _bindings[ctx] = _OSMesaBinding(loader)
    return ctx


_MAKERS = {"egl": _make_egl, "osmesa": _make_osmesa}

# --------------------------------------------------------------------------- the probe
#
# A broken driver does not always fail politely: with GALLIUM_DRIVER naming a driver Mesa
# lacks, OSMesaCreateContextAttribs dies of SIGSEGV, taking the process with it. So before a
# kind is trusted in this process, a short child process makes one context of that kind and
# exits 0; its answer is cached per (kind, the environment Mesa reads) for the process.
# The child's stderr (Mesa's "libEGL warning: ..." lines) is kept off the terminal.

# Environment variables that choose or configure Mesa's driver or the GL libraries loaded.
PROBE_ENVIRONMENT = ("GALLIUM_DRIVER", "LIBGL_ALWAYS_SOFTWARE", "MESA_LOADER_DRIVER_OVERRIDE",
                     "EGL_PLATFORM", "LIBGL_DRIVERS_PATH", "__EGL_VENDOR_LIBRARY_FILENAMES",
                     "__EGL_VENDOR_LIBRARY_DIRS", "LD_LIBRARY_PATH", "LD_PRELOAD",
                     "MESA_GL_VERSION_OVERRIDE", "PYOPENGL_OSMESA_LIBRARY", "OSMESA_LIBRARY",
                     "GLCONTEXT_DEVICE_INDEX")
PROBE_TIMEOUT_S = 30

# The child imports moderngl and, for OSMesa, renderer/gpu/osmesa.py by its path (it imports
# nothing of ours), not the renderer package: about 0.1 s of start-up, not 1 s.
_PROBE_SCRIPT = """
import sys
kind, osmesa_path, required = sys.argv[1], sys.argv[2], int(sys.argv[3])
try:
    import moderngl
    if kind == "egl":
        ctx = moderngl.create_standalone_context(require=required, backend="egl")
    else:
        import importlib.util
        spec = importlib.util.spec_from_file_location("_renderer_osmesa_probe", osmesa_path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        ctx = moderngl.create_context(require=required, standalone=True,
                                      context=module.OSMesaLoader())
    ctx.release()
except Exception as exc:
    print("PROBE-FAILED " + (" ".join(str(exc).split()) or type(exc).__name__), file=sys.stderr)
    sys.exit(3)
"""

_probed: dict[tuple, str | None] = {}


def _probe_key(kind: str) -> tuple:
    return (kind,) + tuple(os.environ.get(name) for name in PROBE_ENVIRONMENT)


def probe(kind: str) -> str | None:
    """None if a context of `kind` ("egl", "osmesa") can be made here, else one line saying
    why (the child's own error, or the signal it died of). Cached for the process."""
    key = _probe_key(kind)
    if key not in _probed:
        _probed[key] = _run_probe(kind)
    return _probed[key]


def _run_probe(kind: str) -> str | None:
    osmesa_path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "osmesa.py")
    try:
        done = subprocess.run([sys.executable, "-c", _PROBE_SCRIPT, kind, osmesa_path,
                               str(REQUIRED_GL)], stdin=subprocess.DEVNULL,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              timeout=PROBE_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return f"{_kind_name(kind)} context did not start in a probe within {PROBE_TIMEOUT_S} s"
    except OSError as exc:                  # no child process at all: trust the kind untested
        return None if exc.errno is not None else _one_line(exc)
    if done.returncode == 0:
        return None
    if done.returncode < 0:
        try:
            cause = signal.Signals(-done.returncode).name
        except ValueError:
            cause = f"signal {-done.returncode}"
        return f"{_kind_name(kind)} context failed in a probe (the process died of {cause})"
    lines = done.stderr.decode("utf-8", errors="replace").splitlines()
    said = [line[len("PROBE-FAILED "):] for line in lines if line.startswith("PROBE-FAILED ")]
    return _one_line(RuntimeError(said[-1] if said else f"the probe exited {done.returncode}"))


def _kind_name(kind: str) -> str:
    return "EGL" if kind == "egl" else "OSMesa"


def _driver_hint() -> str | None:
    driver = os.environ.get("GALLIUM_DRIVER")
    if driver is not None:
        return (f"is GALLIUM_DRIVER={driver} a driver Mesa has? (unset it, or set it to "
                f"llvmpipe or softpipe)")
    return None


def make_context(kind: str = "auto") -> moderngl.Context:
    """A new headless moderngl context (OpenGL 3.3 core or newer), current on return.

    kind: "egl", "osmesa", or "auto" (EGL, then OSMesa). Raises ContextError, one line naming
    the Debian packages to install, when no context of the asked kind starts.
    """
    if kind not in KINDS:
        raise ContextError(f"unknown GL context kind {kind!r}: choose one of {', '.join(KINDS)}")
    tried = ("egl", "osmesa") if kind == "auto" else (kind,)
    failures = []
    for name in tried:
        problem = probe(name)             # a child process: a driver's crash is not ours
        if problem is not None:
            failures.append(f"{name}: {problem}")
            continue
        try:
            return _MAKERS[name]()
        except Exception as exc:          # glcontext raises bare Exception
            failures.append(f"{name}: {_one_line(exc)}")
    hint = _driver_hint()
    if hint is None:
        packages = " or ".join(f"{PACKAGES[name]} (for {_kind_name(name)})" for name in tried)
        hint = f"install the Debian packages {packages}"
    raise ContextError(f"no headless OpenGL {REQUIRED_GL // 100}.{REQUIRED_GL % 100 // 10} context "
                       f"could be made ({'; '.join(failures)}); {hint}")


def adopt_context(ctx: moderngl.Context, make_current, release, get_proc_address) -> None:
    """Treat `ctx`, made and made current by a window library, as one of ours (kind "window"):
    `make_current()`, `release()` (no context current) and `get_proc_address(name) -> int`
    are that library's (glfw.make_context_current(window), glfw.make_context_current(None),
    glfw.get_proc_address)."""
    global _current_window
    binding = _bindings[ctx] = _WindowBinding(make_current, release, get_proc_address)
    _current_window = binding


def before_window_context() -> None:
    """Call before a window library makes a context (renderer/viewer/window.py; glfw makes it
    current as it creates it): no EGL context may be current on the thread then (see _WindowBinding), or GLX refuses
    (BadAccess, which Xlib's default handler turns into the end of the process)."""
    _release_window()
    _release_egl()


def context_kind(ctx: moderngl.Context) -> str:
    """"egl" or "osmesa" for a context from make_context(), "window" for one adopted from a
    window library (adopt_context), "external" for any other."""
    binding = _bindings.get(ctx)
    return binding.kind if binding is not None else "external"


def activate(ctx: moderngl.Context) -> None:
    """Make `ctx` current on this thread if it is one of ours; others are left to the caller."""
    binding = _bindings.get(ctx)
    if binding is not None and binding.needs_binding():
        binding.make_current()


def gl_function(ctx: moderngl.Context, name: str, restype, *argtypes):
    """A ctypes function for a GL entry point moderngl does not wrap, or None if unavailable.

    Our contexts answer through their own loader; for an external context we ask libEGL,
    whose (libglvnd) entry points dispatch to whichever context is current.
    """
    binding = _bindings.get(ctx)
    try:
        address = binding.get_proc_address(name) if binding is not None else \
            _load_egl().eglGetProcAddress(name.encode("ascii"))
    except OSError:
        return None
    if not address:
        return None
    return ctypes.CFUNCTYPE(restype, *argtypes)(address)


def release_context(ctx: moderngl.Context) -> None:
    """Release a context (ours or not); calling it twice is harmless."""
    binding = _bindings.pop(ctx, None)
    if binding is not None:
        try:
            binding.make_current()
        except ContextError:
            pass                          # already destroyed by a direct ctx.release()
    ctx.release()
    if binding is not None:
        binding.after_release()
