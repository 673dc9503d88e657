/*
 * retrokit.native._host: the CPython face of the libretro host.
 *
 * Its types live in host_emulator.c (Emulator, Memory) and host_runner.c
 * (Runner), its functions in host_functions.c; this file makes the module.
 */
#include "host.h"

#include "fields.h"

PyObject *CoreError, *StateError, *InvalidArgumentError;

static PyMethodDef module_methods[] = {
    {"read_fields", (PyCFunction)(void (*)(void))rk_py_read_fields, METH_FASTCALL, "Decode RAM fields by a plan."},
    {"pack_buttons", (PyCFunction)(void (*)(void))rk_py_pack_buttons, METH_FASTCALL,
     "pack_buttons(action, buttons, out[, table]): one bit per nonzero item, a mask per player, looked up in table if "
     "given; False for an unknown format."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef host_module = {
    PyModuleDef_HEAD_INIT, "retrokit.native._host", "Private native host for libretro cores.", -1, module_methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__host(void) {
    PyObject *errors = PyImport_ImportModule("retrokit.errors");
    if (!errors) return NULL;
    CoreError = PyObject_GetAttrString(errors, "CoreError");
    StateError = PyObject_GetAttrString(errors, "StateError");
    InvalidArgumentError = PyObject_GetAttrString(errors, "InvalidArgumentError");
    Py_DECREF(errors);
    if (!CoreError || !StateError || !InvalidArgumentError) return NULL;
    if (PyType_Ready(&EmulatorType) < 0 || PyType_Ready(&MemoryType) < 0 || PyType_Ready(&RunnerType) < 0) return NULL;
    PyObject *m = PyModule_Create(&host_module);
    if (!m) return NULL;
    Py_INCREF(&EmulatorType);
    PyModule_AddObject(m, "Emulator", (PyObject *)&EmulatorType);
    Py_INCREF(&RunnerType);
    PyModule_AddObject(m, "Runner", (PyObject *)&RunnerType);
    PyModule_AddIntConstant(m, "MEMORY_SAVE_RAM", RK_RETRO_MEMORY_SAVE_RAM);
    PyModule_AddIntConstant(m, "MEMORY_RTC", RK_RETRO_MEMORY_RTC);
    PyModule_AddIntConstant(m, "MEMORY_SYSTEM_RAM", RK_RETRO_MEMORY_SYSTEM_RAM);
    PyModule_AddIntConstant(m, "MEMORY_VIDEO_RAM", RK_RETRO_MEMORY_VIDEO_RAM);
    PyModule_AddIntConstant(m, "MAX_PORTS", RK_MAX_PORTS);
    PyModule_AddIntConstant(m, "PIXEL_FORMAT_0RGB1555", RK_RETRO_PIXEL_FORMAT_0RGB1555);
    PyModule_AddIntConstant(m, "PIXEL_FORMAT_XRGB8888", RK_RETRO_PIXEL_FORMAT_XRGB8888);
    PyModule_AddIntConstant(m, "PIXEL_FORMAT_RGB565", RK_RETRO_PIXEL_FORMAT_RGB565);
    PyModule_AddIntConstant(m, "PLAN_COLUMNS", RK_PLAN_COLUMNS);
    return m;
}
