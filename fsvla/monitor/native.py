"""The native contact reader (``native/contacts.cpp``): built on first use, loaded, used.

Reading contacts through SAPIEN's Python bindings costs microseconds a contact point, 25
substeps a control step, and is most of the monitor's cost while a gripper holds a
watched object (``docs/monitor.md``). The native reader folds the same quantities as
:class:`fsvla.monitor.probe.Probe`'s Python reader (free bodies' net force and torque,
kept pairs' force and torque maxima, the last substep's pair forces) straight from the
report map SAPIEN keeps, in one call a substep.

It is compiled once per SAPIEN version and source into a cache folder
(``$FSVLA_CACHE_DIR``, else ``$XDG_CACHE_HOME/fsvla``, else ``~/.cache/fsvla``) with the
system C++ compiler (``$CXX``, else ``c++``) against the headers SAPIEN's wheel ships and
Eigen's (``$EIGEN_INCLUDE_DIR``, else ``/usr/include/eigen3``). Pointers come from
pybind11's cross-module conduit, so nothing links against SAPIEN's module. Where any of
this fails (no compiler, no Eigen, another SAPIEN build), :func:`native_library` says why
in the log and returns None, and the probe reads contacts in Python: slower, the same
numbers. ``FSVLA_NATIVE_CONTACTS=0`` turns the native reader off.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import importlib.machinery
import importlib.util
import logging
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .state import NET, ContactMaxima

log = logging.getLogger(__name__)

SOURCE = Path(__file__).with_name("native") / "contacts.cpp"
BOUND_SOURCE = SOURCE.with_name("bound.cpp")
SWITCH = "FSVLA_NATIVE_CONTACTS"
_ROWS = 64  # initial capacity of the row buffers; they grow when a reading needs more

#: The capsule name pybind11's conduit expects: ``typeid(std::type_info).name()`` in the
#: C++ runtime SAPIEN uses (libstdc++).
TYPE_INFO_CAPSULE = b"St9type_info"

# flags of a frame in a reader (contacts.cpp's Flags)
ANY_PAIR, ROBOT_PAIRS, TORQUE, ROBOT_LINK = 1, 2, 4, 8


class NativeUnavailable(RuntimeError):
    """Why the native reader cannot be used here."""


def cache_dir() -> Path:
    root = os.environ.get("FSVLA_CACHE_DIR")
    if root:
        return Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "fsvla"


def _sapien_include() -> Path:
    import sapien

    include = Path(sapien.__file__).parent / "include"
    if not (include / "sapien" / "physx" / "simulation_callback.hpp").is_file():
        raise NativeUnavailable(f"SAPIEN {sapien.__version__} ships no C++ headers ({include})")
    return include


def _eigen_include() -> Path:
    for candidate in (os.environ.get("EIGEN_INCLUDE_DIR"), "/usr/include/eigen3", "/usr/local/include/eigen3"):
        if candidate and (Path(candidate) / "Eigen" / "Dense").is_file():
            return Path(candidate)
    raise NativeUnavailable("Eigen's headers were not found (install libeigen3-dev, or set EIGEN_INCLUDE_DIR)")


def _compiler() -> str:
    compiler = os.environ.get("CXX") or shutil.which("c++") or shutil.which("g++")
    if not compiler:
        raise NativeUnavailable("no C++ compiler (install g++, or set CXX)")
    return compiler


def _compile(source: Path, stem: str, key: Sequence[bytes], flags: Sequence[str], target_dir: Path | None) -> Path:
    """``source`` compiled into a shared library in the cache (``stem-<digest>.so``), unless
    the cache holds the build for this source, ``key`` and compiler."""
    compiler = _compiler()
    digest = hashlib.sha256()
    for part in (source.read_bytes(), *key, compiler.encode()):
        digest.update(part)
    folder = target_dir or cache_dir() / "native"
    target = folder / f"{stem}-{digest.hexdigest()[:16]}.so"
    if target.is_file():
        return target
    folder.mkdir(parents=True, exist_ok=True)
    # a private name, then an atomic rename: processes building at once never see a part
    fd, partial = tempfile.mkstemp(dir=folder, prefix=f".{stem}-", suffix=".so")
    os.close(fd)
    command = [compiler, "-O2", "-std=c++20", "-shared", "-fPIC", "-w", *flags, str(source), "-o", partial]
    try:
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
        except (OSError, subprocess.SubprocessError) as error:
            raise NativeUnavailable(f"could not run the C++ compiler {compiler!r}: {error}") from error
        if done.returncode != 0:
            tail = " ".join(done.stderr.strip().splitlines()[-3:])
            raise NativeUnavailable(f"compiling {source.name} failed: {tail}")
        os.replace(partial, target)
    finally:
        if os.path.exists(partial):
            os.unlink(partial)
    return target


def build(target_dir: Path | None = None) -> Path:
    """The contact reader's shared library, compiled now unless the cache holds this
    source's build for this SAPIEN. Raises :class:`NativeUnavailable` with the reason when
    it cannot be built."""
    import sapien

    include, eigen = _sapien_include(), _eigen_include()
    # -z defs: a symbol SAPIEN's headers declare but nothing defines fails here, not at load
    flags = ["-Wl,-z,defs", f"-I{include}", f"-I{include / 'physx' / 'include'}", f"-I{eigen}"]
    return _compile(SOURCE, "contacts", (sapien.__version__.encode(), str(include).encode()), flags, target_dir)


def _python_include() -> Path:
    include = Path(sysconfig.get_paths()["include"])
    if not (include / "Python.h").is_file():
        raise NativeUnavailable(f"this Python's C headers are not installed ({include}; install python3-dev)")
    return include


def build_bound(target_dir: Path | None = None) -> Path:
    """The bound-call extension module (``native/bound.cpp``) for this interpreter."""
    include = _python_include()
    key = (sys.version.encode(), str(sysconfig.get_config_var("EXT_SUFFIX")).encode(), str(include).encode())
    # Python's own symbols resolve against the interpreter that loads it, as any extension's
    return _compile(BOUND_SOURCE, "bound", key, [f"-I{include}"], target_dir)


@functools.cache
def bound_calls() -> Any | None:
    """The bound-call module (``bind``), or None where it cannot be built (the reason is
    logged once): callers then keep their ctypes calls, which cost more a call."""
    if os.environ.get(SWITCH, "1").strip().lower() in {"0", "false", "no", "off"}:
        return None
    try:
        path = build_bound()
        loader = importlib.machinery.ExtensionFileLoader("_fsvla_bound", str(path))
        spec = importlib.util.spec_from_file_location("_fsvla_bound", path, loader=loader)
        if spec is None:
            raise NativeUnavailable(f"cannot load {path}")
        module = importlib.util.module_from_spec(spec)
        loader.exec_module(module)
        return module
    except (NativeUnavailable, ImportError, OSError, subprocess.SubprocessError) as error:
        # the numbers are the same either way, only each call costs a microsecond more
        log.info("bound native calls unavailable, calling the contact reader through ctypes: %s", error)
        return None


class NativeLibrary:
    """The loaded reader library and the means to get SAPIEN's C++ pointers."""

    def __init__(self, path: Path):
        lib = ctypes.CDLL(str(path))
        p, u64, i64, f64 = ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint64), ctypes.c_int64, ctypes.c_double
        f64p = ctypes.POINTER(ctypes.c_double)
        for name, restype, argtypes in (
                ("fsvla_system_type", p, []), ("fsvla_component_type", p, []),
                ("fsvla_contact_count", i64, [p]),
                ("fsvla_reader_new", p, [p]), ("fsvla_reader_free", None, [p]),
                ("fsvla_reader_set", None, [p, p, ctypes.c_uint32, ctypes.c_int32]),
                ("fsvla_reader_add_free", None, [p, p, ctypes.c_int32, f64, f64p, f64p, f64p]),
                ("fsvla_reader_reset", None, [p]),
                ("fsvla_reader_fold", None, [p, f64, ctypes.c_int32]),
                ("fsvla_reader_take_free", None, [p, f64p, ctypes.c_int32]),
                ("fsvla_reader_take", i64, [p, u64, f64p, i64, ctypes.c_int32]),
                ("fsvla_reader_read", i64, [p, u64, f64p, i64]),
                ("fsvla_snapshot_new", p, [p, p, p, i64]), ("fsvla_snapshot_free", None, [p]),
                ("fsvla_snapshot_buffers", None, [p, p, p, p, p, i64, p, p, i64, p]),
                ("fsvla_snapshot_take", None, [p, f64, ctypes.c_int32]),
                ("fsvla_entity_name", i64, [p, ctypes.c_char_p, i64])):
            function = getattr(lib, name)
            function.restype, function.argtypes = restype, argtypes
        self.lib = lib
        # private prototypes of the C API (ctypes.pythonapi's function objects are shared)
        self._capsule_new = _c_api("PyCapsule_New", ctypes.py_object, p, ctypes.c_char_p, p)  # a new reference
        self._capsule_name = _c_api("PyCapsule_GetName", ctypes.c_char_p, ctypes.py_object)
        self._capsule_pointer = _c_api("PyCapsule_GetPointer", p, ctypes.py_object, ctypes.c_char_p)
        self._abi_ids = _pybind_abi_ids()

    def pointer(self, obj: Any, type_info: int) -> int:
        """The C++ pointer behind a SAPIEN object, as the type ``type_info`` names."""
        conduit = getattr(obj, "_pybind11_conduit_v1_", None)
        capsule = self._capsule_new(type_info, TYPE_INFO_CAPSULE, None)
        for abi in self._abi_ids if conduit is not None else ():
            result = conduit(abi, capsule, b"raw_pointer_ephemeral")
            if result is not None:
                return int(self._capsule_pointer(result, self._capsule_name(result)))
        raise NativeUnavailable(f"SAPIEN's bindings do not hand out a {type(obj).__name__}'s C++ pointer")

    def system(self, physx_system: Any) -> int:
        """The PhysxSystemCpu behind ``scene.physx_system``, checked against its contact list."""
        pointer = self.pointer(physx_system, self.lib.fsvla_system_type())
        if self.lib.fsvla_contact_count(pointer) != len(physx_system.get_contacts()):
            raise NativeUnavailable("the native contact map disagrees with SAPIEN's contact list")
        return pointer

    def component(self, component: Any) -> int:
        return self.pointer(component, self.lib.fsvla_component_type())

    def entity_name(self, pointer: int) -> str:
        buffer = ctypes.create_string_buffer(256)
        n = self.lib.fsvla_entity_name(pointer, buffer, len(buffer))
        if n >= len(buffer):
            buffer = ctypes.create_string_buffer(n + 1)
            self.lib.fsvla_entity_name(pointer, buffer, len(buffer))
        return buffer.value.decode("utf-8", "replace")


def _c_api(name: str, restype: Any, *argtypes: Any) -> Any:
    return ctypes.PYFUNCTYPE(restype, *argtypes)((name, ctypes.pythonapi))


def _pybind_abi_ids() -> tuple[bytes, ...]:
    """The platform ABI ids of the pybind11 modules loaded in this interpreter (the keys
    of their shared internals), e.g. ``system_libstdcpp_gxx_abi_1xxx_use_cxx11_abi_1``."""
    interpreter = _c_api("PyInterpreterState_Get", ctypes.c_void_p)()
    # a borrowed reference: taken as an address and read as an object (which counts it)
    address = _c_api("PyInterpreterState_GetDict", ctypes.c_void_p, ctypes.c_void_p)(interpreter)
    state = ctypes.cast(address, ctypes.py_object).value if address else {}
    ids = []
    for key in list(state):
        match = re.fullmatch(r"__pybind11_internals_v\d+_(.+)__", str(key))
        if match:
            ids.append(match.group(1).encode())
    return tuple(ids)


@functools.cache
def native_library() -> NativeLibrary | None:
    """The native reader library for this process, or None (the reason is logged once)."""
    if os.environ.get(SWITCH, "1").strip().lower() in {"0", "false", "no", "off"}:
        log.info("native contact reader switched off (%s)", SWITCH)
        return None
    try:
        import sapien  # noqa: F401  (its bindings register the types the conduit finds)

        return NativeLibrary(build())
    except (NativeUnavailable, OSError, subprocess.SubprocessError) as error:
        log.warning("native contact reader unavailable, reading contacts in Python: %s", error)
        return None


class NativeSnapshot:
    """A control step's reading in one native call (``fsvla_snapshot_take``): the poses of
    a fixed list of components, the scan reader's maxima (then forgotten) and, if asked,
    the last reader's current pairs. The poses are the matrices SAPIEN's
    ``entity_pose.to_transformation_matrix()`` gives, bit for bit; the rest is what
    :meth:`NativeReader.take` and :meth:`NativeReader.read` give one by one, at a
    Python-to-C call each, which costs microseconds right after PhysX stepped."""

    def __init__(self, library: NativeLibrary, scan: NativeReader, last: NativeReader | None,
                 pointers: Sequence[int]):
        lib = self._lib = library.lib
        self._scan, self._last = scan, last
        components = np.array(pointers, dtype=np.uint64)
        self._handle = lib.fsvla_snapshot_new(scan._handle, last._handle if last is not None else None,
                                              components.ctypes.data, len(components))
        self._poses = np.zeros((len(components), 4, 4), dtype=np.float32)  # copied out every step
        self._counts = np.zeros(2, dtype=np.int64)
        self._grown = (-1, -1)
        self._point()
        bound, address = bound_calls(), ctypes.cast(lib.fsvla_snapshot_take, ctypes.c_void_p).value
        # the calls live only here, so they keep nothing (keeping self would be a cycle
        # through a capsule, which the collector cannot see through)
        self._calls = tuple(bound.bind(address, self._handle, 0.0, flag, None) if bound is not None
                            else functools.partial(lib.fsvla_snapshot_take, self._handle, 0.0, flag)
                            for flag in (0, 1))

    def _point(self) -> None:
        """Tell the native side where the buffers are (again after a reader grew its own)."""
        scan, last = self._scan, self._last
        self._grown = self._generations()
        self._lib.fsvla_snapshot_buffers(
            self._handle, self._poses.ctypes.data, scan._free_values.ctypes.data, scan._pairs.ctypes.data,
            scan._values.ctypes.data, scan._rows, last._pairs.ctypes.data if last is not None else None,
            last._values.ctypes.data if last is not None else None, last._rows if last is not None else 0,
            self._counts.ctypes.data)

    def _generations(self) -> tuple[int, int]:
        """How many times each reader has made its buffers (-1 for no last reader)."""
        return self._scan.grown, self._last.grown if self._last is not None else -1

    def __del__(self) -> None:
        handle, self._handle = getattr(self, "_handle", None), None
        if handle:
            self._lib.fsvla_snapshot_free(handle)

    def take(self, maxima: ContactMaxima, read_last: bool, inv_dt: float) -> tuple[
            np.ndarray, dict[tuple[str, str], np.ndarray]]:
        """(a new (n, 4, 4) float32 pose stack, the last substep's pair forces or {} unless
        ``read_last``); the scan reader's maxima are added to ``maxima`` and forgotten."""
        read_last = read_last and self._last is not None
        scan = self._scan
        if self._generations() != self._grown:
            self._point()  # a reader grew its buffers since (a take or read of its own)
        self._calls[read_last]()
        taken, read = self._counts.tolist()
        if scan._free:
            scan._free_rows(maxima)
        if taken < 0:  # more pair rows than the buffers held: nothing was taken yet
            scan._pair_rows(maxima, scan._call(self._lib.fsvla_reader_take, True))
            self._point()
        else:
            scan._pair_rows(maxima, taken)
        last: dict[tuple[str, str], np.ndarray] = {}
        if read_last:
            assert self._last is not None
            if read < 0:
                last = self._last.read(inv_dt)
                self._point()
            else:
                last = self._last._read_rows(read, inv_dt)
        return self._poses.copy(), last


@dataclass(frozen=True)
class FreeBodySpec:
    """A free body whose net contact force (and torque) the reader folds every substep."""

    frame: str
    component: Any
    torque: bool
    gravity: tuple[float, float, float]


class NativeReader:
    """One filter's reading over one scene: per-substep folds, maxima taken per control
    step (:meth:`take`), or the current reports' pair impulses (:meth:`read`).

    ``system`` is :meth:`NativeLibrary.system`'s pointer, ``pointers`` every frame's
    component pointer (:meth:`NativeLibrary.component`); free bodies are frames of it."""

    def __init__(self, library: NativeLibrary, system: int, pointers: Mapping[str, int], *,
                 any_pair: Iterable[str] = (), robot_pairs: Iterable[str] = (), torque: Iterable[str] = (),
                 free_bodies: Sequence[FreeBodySpec] = ()):
        self._library, lib = library, library.lib
        self._lib = lib
        self._handle = lib.fsvla_reader_new(system)
        any_pair, robot_pairs, torque = frozenset(any_pair), frozenset(robot_pairs), frozenset(torque)
        robots: dict[str, int] = {}
        self._frames: dict[int, str] = {}
        for frame, pointer in pointers.items():
            flags = ((ANY_PAIR if frame in any_pair else 0) | (ROBOT_PAIRS if frame in robot_pairs else 0)
                     | (TORQUE if frame in torque else 0))
            robot = -1
            if frame.startswith("@"):
                flags |= ROBOT_LINK
                robot = robots.setdefault(frame.split(":", 1)[0], len(robots))
            lib.fsvla_reader_set(self._handle, pointer, flags, robot)
            self._frames[pointer] = frame
        self._free = [body.frame for body in free_bodies]
        for body in free_bodies:
            c = body.component
            inertia = (ctypes.c_double * 3)(*(float(v) for v in c.inertia))
            cmass_q = (ctypes.c_double * 4)(*(float(v) for v in c.cmass_local_pose.q))
            gravity = (ctypes.c_double * 3)(*body.gravity)
            lib.fsvla_reader_add_free(self._handle, pointers[body.frame], int(body.torque), float(c.mass),
                                      inertia, cmass_q, gravity)
        self._free_values = np.zeros(2 * max(len(self._free), 1))
        self._free_arg = self._free_values.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self.grown = -1  # times the buffers were (re)made: a NativeSnapshot points at them anew
        self._grow(_ROWS)

    def _grow(self, rows: int) -> None:
        self.grown += 1
        self._pairs = np.zeros(2 * rows, dtype=np.uint64)
        self._values = np.zeros(3 * rows)
        self._rows = rows
        self._pairs_arg = self._pairs.ctypes.data_as(ctypes.POINTER(ctypes.c_uint64))
        self._values_arg = self._values.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def __del__(self) -> None:
        handle, self._handle = getattr(self, "_handle", None), None
        if handle:
            self._lib.fsvla_reader_free(handle)

    def frame(self, pointer: int) -> str:
        """The frame of a component pointer; ``?<entity name>`` for a body outside the map."""
        frame = self._frames.get(pointer)
        if frame is None:
            frame = self._frames[pointer] = f"?{self._library.entity_name(pointer)}"
        return frame

    def reset(self) -> None:
        """Forget the maxima and re-read the free bodies' velocities."""
        self._lib.fsvla_reader_reset(self._handle)

    def folder(self, inv_dt: float, scan: bool) -> Callable[[], None]:
        """A callable that folds the substep just taken: free bodies, and the kept pairs if
        ``scan`` (the reader's call with its arguments bound: it runs every substep, so
        through :func:`bound_calls` where it can be built, else ctypes)."""
        bound = bound_calls()
        if bound is not None:
            address = ctypes.cast(self._lib.fsvla_reader_fold, ctypes.c_void_p).value
            return bound.bind(address, self._handle, inv_dt, int(scan), self)
        return functools.partial(self._lib.fsvla_reader_fold, self._handle, inv_dt, scan)

    def take(self, maxima: ContactMaxima, clear: bool = True) -> None:
        """Add the maxima folded since the last take to ``maxima``, then forget them
        (unless not ``clear``)."""
        if self._free:
            self._lib.fsvla_reader_take_free(self._handle, self._free_arg, clear)
            self._free_rows(maxima)
        self._pair_rows(maxima, self._call(self._lib.fsvla_reader_take, clear))

    def _free_rows(self, maxima: ContactMaxima) -> None:
        """Add the free bodies' maxima, as the native side wrote them, to ``maxima``."""
        values = self._free_values.tolist()
        for i, frame in enumerate(self._free):
            force, torque = values[2 * i], values[2 * i + 1]
            if force >= 0.0:
                maxima.add_force(frame, NET, force)
            if torque >= 0.0:
                maxima.add_torque(frame, NET, torque)

    def _pair_rows(self, maxima: ContactMaxima, n: int) -> None:
        """Add the first ``n`` rows of pair maxima in the buffers to ``maxima``."""
        if not n:
            return
        pairs, values = self._pairs[:2 * n].tolist(), self._values[:3 * n].tolist()
        for i in range(n):
            a, b = self.frame(pairs[2 * i]), self.frame(pairs[2 * i + 1])
            force, torque_a, torque_b = values[3 * i:3 * i + 3]
            if force > 0.0:
                maxima.add_force(a, b, force)
            if torque_a > 0.0:
                maxima.add_torque(a, b, torque_a)
            if torque_b > 0.0:
                maxima.add_torque(b, a, torque_b)

    def read(self, inv_dt: float) -> dict[tuple[str, str], np.ndarray]:
        """Force on the first frame by the second, both orders, for the kept pairs of the
        current reports (the last substep)."""
        return self._read_rows(self._call(self._lib.fsvla_reader_read), inv_dt)

    def _read_rows(self, n: int, inv_dt: float) -> dict[tuple[str, str], np.ndarray]:
        """:meth:`read`'s answer from the first ``n`` rows of pair impulses in the buffers."""
        if not n:
            return {}
        pairs = self._pairs[:2 * n].tolist()
        on_first = self._values[:3 * n].reshape(n, 3) * inv_dt
        keys = [(self.frame(pairs[2 * i]), self.frame(pairs[2 * i + 1])) for i in range(n)]
        # one row a component pair, and a frame is one component; the values are rows of one array
        return dict(zip(keys + [(b, a) for a, b in keys], np.concatenate((on_first, -on_first))))

    def _call(self, function: Any, *args: Any) -> int:
        n = function(self._handle, self._pairs_arg, self._values_arg, self._rows, *args)
        if n < 0:  # more rows than the buffers hold: grow and ask again
            self._grow(2 * -n)
            n = function(self._handle, self._pairs_arg, self._values_arg, self._rows, *args)
        return n


__all__ = ["FreeBodySpec", "NativeLibrary", "NativeReader", "NativeSnapshot", "NativeUnavailable", "bound_calls", "build",
           "build_bound", "native_library"]
