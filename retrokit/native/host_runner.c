/*
 * The Runner type of retrokit.native._host: several emulators' frames in one
 * call, on runner.c's threads, with the GIL released once.
 */
#include "host.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#include "runner.h"

typedef struct {
    PyObject_HEAD
    rk_runner runner;
    pid_t pid;
    atomic_int busy;
} RunnerObject;

static int runner_init(RunnerObject *self, PyObject *args, PyObject *kwargs) {
    static char *kwlist[] = {"threads", NULL};
    int threads;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "i", kwlist, &threads)) return -1;
    if (self->runner.workers)
        return rk_py_fail(InvalidArgumentError, "Runner.__init__ was called twice; make a new Runner instead");
    if (threads < 0 || threads > 256)
        return rk_py_fail(InvalidArgumentError, "threads must be 0 to 256, got %d", threads);
    if (rk_runner_init(&self->runner, threads)) return rk_py_fail(CoreError, "cannot start the runner's threads");
    self->pid = getpid();
    return 0;
}

static void runner_dealloc(RunnerObject *self) {
    if (self->runner.workers && self->pid == getpid()) {
        Py_BEGIN_ALLOW_THREADS
        rk_runner_close(&self->runner);
        Py_END_ALLOW_THREADS
    }
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *runner_run(RunnerObject *self, PyObject *args) {
    PyObject *emus, *actions_obj, *screens = Py_None;
    int frames, after = 0;
    if (!PyArg_ParseTuple(args, "OOi|Oi", &emus, &actions_obj, &frames, &screens, &after)) return NULL;
    if (self->pid != getpid())
        return PyErr_Format(CoreError, "this runner was made in another process; make a new one after fork");
    if (frames < 0) return PyErr_Format(InvalidArgumentError, "frames must be 0 or more, got %d", frames);
    if (after < 0) return PyErr_Format(InvalidArgumentError, "after must be 0 or more, got %d", after);
    int expected = 0, ports = 0;
    if (!atomic_compare_exchange_strong(&self->busy, &expected, 1))
        return PyErr_Format(CoreError, "this runner is running in another thread; use one runner per thread");
    PyObject *screen_seq = NULL, *result = NULL;
    rk_task *tasks = NULL;
    Py_buffer actions = {0}, *views = NULL; /* zeroed: releasing one that holds nothing is a no-op */
    Py_ssize_t n = 0, claimed = 0;
    PyObject *seq = PySequence_Fast(emus, "emulators must be a sequence of Emulator objects");
    if (!seq || PyObject_GetBuffer(actions_obj, &actions, PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0) goto done;
    n = PySequence_Fast_GET_SIZE(seq);
    if (screens != Py_None && !(screen_seq = PySequence_Fast(screens, "screens must be a sequence of buffers, or None")))
        goto done;
    RK_CHECK(!screen_seq || PySequence_Fast_GET_SIZE(screen_seq) == n, InvalidArgumentError,
             "expected %zd screen buffers, got %zd", n, PySequence_Fast_GET_SIZE(screen_seq));
    tasks = calloc((size_t)(n > 0 ? n : 1), sizeof(rk_task));
    views = calloc((size_t)(n > 0 ? n : 1), sizeof(Py_buffer));
    RK_CHECK(tasks && views, PyExc_MemoryError, "cannot allocate the tasks of %zd emulators", n);
    for (Py_ssize_t i = 0; i < n; i++) {
        EmulatorObject *emu = (EmulatorObject *)PySequence_Fast_GET_ITEM(seq, i);
        RK_CHECK(Py_IS_TYPE(emu, &EmulatorType), InvalidArgumentError, "emulator %zd is a %s, not a native Emulator",
                 i, Py_TYPE(emu)->tp_name);
        if (i == 0) ports = emu->core.n_ports;
        RK_CHECK(emu->core.n_ports == ports, InvalidArgumentError,
                 "every emulator must have %d ports; emulator %zd has %d", ports, i, emu->core.n_ports);
        if (screen_seq) {
            if (rk_py_get_obs(emu, PySequence_Fast_GET_ITEM(screen_seq, i), &views[i])) goto done;
            tasks[i].screen = views[i].buf;
            tasks[i].screen_height = views[i].ndim == 3 ? (unsigned)views[i].shape[0] : 0;
            tasks[i].screen_width = views[i].ndim == 3 ? (unsigned)views[i].shape[1] : 0;
        }
        if (rk_py_enter(emu, 1)) goto done;
        claimed++;
        tasks[i].core = &emu->core;
        tasks[i].frames = frames;
        tasks[i].after = after;
    }
    RK_CHECK(actions.itemsize == 2 && actions.ndim == 2 && actions.shape[0] == n && actions.shape[1] == ports,
             InvalidArgumentError, "actions must be a uint16 array of shape (%zd, %d): one mask per port per emulator",
             n, ports);
    for (Py_ssize_t i = 0; i < n; i++) tasks[i].actions = (const uint16_t *)actions.buf + i * ports;
    Py_BEGIN_ALLOW_THREADS
    rk_runner_run(&self->runner, tasks, (int)n);
    Py_END_ALLOW_THREADS
    result = PyTuple_New(n);
    for (Py_ssize_t i = 0; result && i < n; i++) PyTuple_SET_ITEM(result, i, PyBool_FromLong(tasks[i].converted));
done:
    for (Py_ssize_t i = 0; i < claimed; i++) rk_py_leave((EmulatorObject *)PySequence_Fast_GET_ITEM(seq, i));
    for (Py_ssize_t i = 0; views && i < n; i++) PyBuffer_Release(&views[i]);
    PyBuffer_Release(&actions);
    atomic_store(&self->busy, 0);
    free(tasks);
    free(views);
    Py_XDECREF(screen_seq);
    Py_XDECREF(seq);
    return result;
}

static PyObject *runner_get_moved(RunnerObject *self, void *closure) {
    return PyLong_FromUnsignedLongLong(self->runner.moved);
}

static PyGetSetDef runner_getset[] = {
    {"moved", (getter)runner_get_moved, NULL,
     "How many times a waiting caller moved a worker that lost its CPU onto its own.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMethodDef runner_methods[] = {
    {"run", (PyCFunction)runner_run, METH_VARARGS,
     "run(emulators, actions, frames, screens=None, after=0): run them all; return whether each screen was converted."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject RunnerType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "retrokit.native._host.Runner",
    .tp_basicsize = sizeof(RunnerObject),
    .tp_dealloc = (destructor)runner_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Runner(threads): worker threads that, with the caller, run several emulators' frames in one call.",
    .tp_methods = runner_methods,
    .tp_getset = runner_getset,
    .tp_init = (initproc)runner_init,
    .tp_new = PyType_GenericNew,
};
