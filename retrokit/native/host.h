/*
 * Shared by the files of retrokit.native._host: the exceptions, the Emulator
 * object, claiming an emulator for a call, and checking arguments. Not part
 * of any interface.
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

/* Emulator's state calls (host_state.c). */
PyObject *rk_py_serialize(EmulatorObject *self, PyObject *unused);
PyObject *rk_py_unserialize(EmulatorObject *self, PyObject *args);
PyObject *rk_py_reload(EmulatorObject *self, PyObject *unused);

/* Emulator's views of its core's memory (host_memory.c). */
PyObject *rk_py_memory(EmulatorObject *self, PyObject *arg);
PyObject *rk_py_memory_maps(EmulatorObject *self, PyObject *unused);
PyObject *rk_py_memory_span(EmulatorObject *self, PyObject *args);

PyObject *rk_py_read_fields(PyObject *module, PyObject *const *args, Py_ssize_t nargs);
PyObject *rk_py_pack_buttons(PyObject *module, PyObject *const *args, Py_ssize_t nargs);

/* Claim an emulator for one call (raises and returns -1 if closed, without a
 * game when one is needed, or busy in another thread); leave releases it
 * and hands the core's queued log lines to Python. */
int rk_py_enter(EmulatorObject *self, int need_game);
void rk_py_leave(EmulatorObject *self);

/* Raise `type` with a printf-style message and return -1 (for int-returning functions). */
int rk_py_fail(PyObject *type, const char *format, ...);

/* For a function that releases what it holds at its `done:` label: unless
 * `ok`, raise `type` with a printf-style message and go there. */
#define RK_CHECK(ok, type, ...) \
    do { if (!(ok)) { PyErr_Format(type, __VA_ARGS__); goto done; } } while (0)

/* Release `view` (a no-op if it holds nothing) and return `result`: the way
 * out of a call that holds a buffer, whether it fails or not. */
PyObject *rk_py_release(Py_buffer *view, PyObject *result);

/* Get `obj` as a writable C-contiguous uint8 array of shape (height, width, 3),
 * of this height and width unless they are 0; else raise and return -1. */
int rk_py_get_screen(PyObject *obj, Py_buffer *view, unsigned height, unsigned width);

/* Get `obj` as where `emu`'s observation goes: with a preprocessor, a writable
 * C-contiguous uint8 array of the observation's size; else a screen buffer of
 * any height and width (rk_py_get_screen). Else raise and return -1. */
int rk_py_get_obs(EmulatorObject *emu, PyObject *obj, Py_buffer *view);

#endif
