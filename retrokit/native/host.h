/*
 * Shared by the files of retrokit.native._host: the exceptions, the Emulator
 * object, and claiming an emulator for a call. Not part of any interface.
 */
#ifndef RETROKIT_HOST_H
#define RETROKIT_HOST_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "core.h"

extern PyObject *CoreError, *StateError, *InvalidArgumentError;

typedef struct {
    PyObject_HEAD
    rk_core core;
    PyObject *log;
    Py_ssize_t exports; /* live buffers onto the core's memory */
    int closed;
} EmulatorObject;

extern PyTypeObject EmulatorType, MemoryType, RunnerType;

/* Claim an emulator for one call (raises and returns -1 if closed, without a
 * game when one is needed, or busy in another thread); leave releases it
 * and hands the core's queued log lines to Python. */
int rk_py_enter(EmulatorObject *self, int need_game);
void rk_py_leave(EmulatorObject *self);

void rk_py_really_close(EmulatorObject *self);

/* Emulator methods defined in host_data.c. */
PyObject *emulator_screen_shape(EmulatorObject *self, PyObject *arg);
PyObject *emulator_screen(EmulatorObject *self, PyObject *arg);
PyObject *emulator_memory(EmulatorObject *self, PyObject *arg);
PyObject *emulator_memory_maps(EmulatorObject *self, PyObject *arg);
PyObject *emulator_capture_audio(EmulatorObject *self, PyObject *arg);
PyObject *emulator_take_audio(EmulatorObject *self, PyObject *arg);
PyObject *emulator_serialize_size(EmulatorObject *self, PyObject *arg);
PyObject *emulator_serialize(EmulatorObject *self, PyObject *arg);
PyObject *emulator_unserialize(EmulatorObject *self, PyObject *arg);

PyObject *rk_py_read_fields(PyObject *module, PyObject *const *args, Py_ssize_t nargs);
PyObject *rk_py_pack_buttons(PyObject *module, PyObject *const *args, Py_ssize_t nargs);

#endif
