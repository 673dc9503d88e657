/*
 * retrokit.native._host: the CPython face of the libretro host.
 *
 * The Emulator type (and the Memory it hands out) lives in host_emulator.c,
 * its state calls in host_state.c, the Runner type in host_runner.c, the module's functions in
 * host_functions.c; this file makes the module, with the helpers all share.
 */
#include "host.h"

#include "fields.h"

PyObject *CoreError, *StateError, *InvalidArgumentError;

int rk_py_fail(PyObject *type, const char *format, ...) {
    va_list args;
    va_start(args, format);
    PyErr_FormatV(type, format, args);
    va_end(args);
    return -1;
}

PyObject *rk_py_release(Py_buffer *view, PyObject *result) {
    PyBuffer_Release(view); /* a no-op on a zeroed view */
    return result;
}

int rk_py_get_screen(PyObject *obj, Py_buffer *view, unsigned height, unsigned width) {
    if (PyObject_GetBuffer(obj, view, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0) return -1;
    const char *f = view->format ? view->format : "B";
    if (view->ndim == 3 && view->shape[2] == 3 && view->itemsize == 1 && (f[0] == 'B' || f[0] == 'c') && !f[1] &&
        (!height || (view->shape[0] == (Py_ssize_t)height && view->shape[1] == (Py_ssize_t)width)))
        return 0;
    char shape[48] = "height, width";
    if (height) snprintf(shape, sizeof shape, "%u, %u", height, width);
    PyErr_Format(InvalidArgumentError,
                 "the screen buffer must be a C-contiguous uint8 array of shape (%s, 3), got %d dimensions of "
                 "%zd-byte items (format %s); make it with numpy.empty(emulator.screen_shape() + (3,), numpy.uint8)",
                 shape, view->ndim, view->itemsize, f);
    PyBuffer_Release(view);
    return -1;
}

int rk_py_get_obs(EmulatorObject *emu, PyObject *obj, Py_buffer *view) {
    rk_prep *prep = emu->core.prep;
    if (!prep) return rk_py_get_screen(obj, view, 0, 0);
    if (PyObject_GetBuffer(obj, view, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0) return -1;
    const char *f = view->format ? view->format : "B";
    size_t size = rk_prep_obs_size(prep);
    if (view->itemsize == 1 && (f[0] == 'B' || f[0] == 'c') && !f[1] && (size_t)view->len == size) return 0;
    PyErr_Format(InvalidArgumentError,
                 "the observation buffer must be a C-contiguous uint8 array of %zu bytes (the preprocessed "
                 "observation's shape), got %zd bytes of format %s; make it with numpy.empty of the env's "
                 "observation_space.shape", size, view->len, f);
    PyBuffer_Release(view);
    return -1;
}

static PyMethodDef module_methods[] = {
    {"read_fields", (PyCFunction)(void (*)(void))rk_py_read_fields, METH_FASTCALL, "Decode RAM fields by a plan."},
    {"pack_buttons", (PyCFunction)(void (*)(void))rk_py_pack_buttons, METH_FASTCALL,
     "pack_buttons(action, buttons, out[, table]): a button mask per player; False for an unknown format."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef host_module = {.m_base = PyModuleDef_HEAD_INIT, .m_name = "retrokit.native._host",
    .m_doc = "Private native host for libretro cores.", .m_size = -1, .m_methods = module_methods};

PyMODINIT_FUNC PyInit__host(void) {
    PyObject *errors = PyImport_ImportModule("retrokit.errors");
    if (!errors) return NULL;
    CoreError = PyObject_GetAttrString(errors, "CoreError");
    StateError = PyObject_GetAttrString(errors, "StateError");
    InvalidArgumentError = PyObject_GetAttrString(errors, "InvalidArgumentError");
    Py_DECREF(errors);
    if (!CoreError || !StateError || !InvalidArgumentError) return NULL;
    if (PyType_Ready(&MemoryType) < 0) return NULL;
    PyObject *m = PyModule_Create(&host_module);
    if (!m || PyModule_AddType(m, &EmulatorType) < 0 || PyModule_AddType(m, &RunnerType) < 0) {
        Py_XDECREF(m);
        return NULL;
    }
    PyModule_AddIntConstant(m, "MEMORY_SYSTEM_RAM", RK_RETRO_MEMORY_SYSTEM_RAM);
    PyModule_AddIntConstant(m, "MAX_PORTS", RK_MAX_PORTS);
    PyModule_AddIntConstant(m, "PLAN_COLUMNS", RK_PLAN_COLUMNS);
    PyModule_AddIntConstant(m, "VIDEO_ALL", RK_VIDEO_ALL);
    PyModule_AddIntConstant(m, "VIDEO_LAST", RK_VIDEO_LAST);
    PyModule_AddIntConstant(m, "VIDEO_NONE", RK_VIDEO_NONE);
    return m;
}
