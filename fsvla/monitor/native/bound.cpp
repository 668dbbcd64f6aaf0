// A Python callable that calls one C function with its arguments bound in C.
//
// The env calls the monitor's per-substep fold 25 times a control step, right after
// PhysX has stepped and pushed the interpreter out of the CPU's caches. Through ctypes
// that call costs about 1.2 us there even for a function that does nothing (argument
// conversion, libffi), which was a fifth of the monitor's time in some scenarios. A
// builtin function whose arguments already sit in a C struct costs a fraction of that.
//
// bind(function, handle, value, flag, keep) -> callable: calling it with no arguments
// calls `function(handle, value, flag)`, a `void (*)(void *, double, int32_t)` given by
// address (fsvla.monitor.native builds it against this interpreter's headers; where it
// cannot, the caller keeps its ctypes call). `keep` is held for as long as the callable
// lives: the object that owns `handle`, so the handle cannot be freed under it.

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <cstdint>

namespace {

using Function = void (*)(void *, double, int32_t);

constexpr const char *kCapsule = "fsvla.bound";

struct Bound {
  Function function;
  void *handle;
  double value;
  int32_t flag;
  PyObject *keep;
};

void free_bound(PyObject *capsule) {
  auto *bound = static_cast<Bound *>(PyCapsule_GetPointer(capsule, kCapsule));
  if (bound) {
    Py_XDECREF(bound->keep);
    PyMem_Free(bound);
  }
}

PyObject *call_bound(PyObject *capsule, PyObject *) {
  auto *bound = static_cast<Bound *>(PyCapsule_GetPointer(capsule, kCapsule));
  if (!bound) return nullptr;
  bound->function(bound->handle, bound->value, bound->flag);
  Py_RETURN_NONE;
}

PyMethodDef call_def = {"bound_call", call_bound, METH_NOARGS,
                        "Call the bound C function with its bound arguments."};

PyObject *bind(PyObject *, PyObject *args) {
  unsigned long long function = 0, handle = 0;
  double value = 0.0;
  int flag = 0;
  PyObject *keep = nullptr;
  if (!PyArg_ParseTuple(args, "KKdiO", &function, &handle, &value, &flag, &keep)) return nullptr;
  if (!function) {
    PyErr_SetString(PyExc_ValueError, "bind: the function address is null");
    return nullptr;
  }
  auto *bound = static_cast<Bound *>(PyMem_Malloc(sizeof(Bound)));
  if (!bound) return PyErr_NoMemory();
  *bound = {reinterpret_cast<Function>(function), reinterpret_cast<void *>(handle), value,
            static_cast<int32_t>(flag), keep};
  Py_INCREF(keep);
  PyObject *capsule = PyCapsule_New(bound, kCapsule, free_bound);
  if (!capsule) {
    Py_DECREF(keep);
    PyMem_Free(bound);
    return nullptr;
  }
  PyObject *callable = PyCFunction_New(&call_def, capsule);  // holds the capsule
  Py_DECREF(capsule);
  return callable;
}

PyMethodDef methods[] = {
    {"bind", bind, METH_VARARGS,
     "bind(function, handle, value, flag, keep): a callable that calls function(handle, value, flag)."},
    {nullptr, nullptr, 0, nullptr}};

PyModuleDef module = {PyModuleDef_HEAD_INIT, "_fsvla_bound",
                      "C calls with their arguments bound (fsvla.monitor.native).", -1, methods};

}  // namespace

PyMODINIT_FUNC PyInit__fsvla_bound() { return PyModule_Create(&module); }
