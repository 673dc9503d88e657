/*
 * retrokit.native._host: the CPython face of the libretro host.
 *
 * The Emulator type (and the Memory it hands out) lives in host_emulator.c;
 * this file makes the module, with the helpers both share, its functions
 * (decoding RAM fields by a plan, packing button arrays into RetroPad masks)
 * and its Runner type (several emulators' frames in one call, on runner.c's
 * threads).
 */
#include "host.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#include "fields.h"
#include "runner.h"

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

#define RK_MAX_BUFFERS 16

/* The decoded values as a dict; 8-byte unsigned fields keep their true value. */
static PyObject *values_by_name(PyObject *names, const int64_t *plan, const int64_t *values, Py_ssize_t rows) {
    PyObject *dict = _PyDict_NewPresized(rows);
    for (Py_ssize_t r = 0; dict && r < rows; r++) {
        const int64_t *row = plan + r * RK_PLAN_COLUMNS;
        int wide = row[RK_PLAN_KIND] == RK_KIND_UNSIGNED && row[RK_PLAN_WIDTH] == 8;
        PyObject *v = wide ? PyLong_FromUnsignedLongLong((unsigned long long)values[r]) : PyLong_FromLongLong(values[r]);
        if (!v || PyDict_SetItem(dict, PyTuple_GET_ITEM(names, r), v) < 0) Py_CLEAR(dict);
        Py_XDECREF(v);
    }
    return dict;
}

static PyObject *read_fields(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3 && nargs != 4) return PyErr_Format(PyExc_TypeError, "read_fields() takes (buffers, plan, out[, names])");
    PyObject *names = nargs == 4 && args[3] != Py_None ? args[3] : NULL;
    if (names && !PyTuple_Check(names)) return PyErr_Format(PyExc_TypeError, "names must be a tuple of str");
    PyObject *seq = PySequence_Fast(args[0], "buffers must be a sequence of buffers");
    if (!seq) return NULL;
    Py_ssize_t nbuf = PySequence_Fast_GET_SIZE(seq), got = 0;
    Py_buffer bufs[RK_MAX_BUFFERS], plan = {0}, out = {0}; /* releasing a zeroed one is a no-op */
    const uint8_t *ptrs[RK_MAX_BUFFERS];
    PyObject *result = NULL;
    RK_CHECK(nbuf <= RK_MAX_BUFFERS, InvalidArgumentError, "at most %d buffers, got %zd", RK_MAX_BUFFERS, nbuf);
    for (; got < nbuf; got++) {
        if (PyObject_GetBuffer(PySequence_Fast_GET_ITEM(seq, got), &bufs[got], PyBUF_SIMPLE) < 0) goto done;
        ptrs[got] = bufs[got].buf;
    }
    if (PyObject_GetBuffer(args[1], &plan, PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0 ||
        PyObject_GetBuffer(args[2], &out, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0)
        goto done;
    RK_CHECK(plan.itemsize == 8 && plan.ndim == 2 && plan.shape[1] == RK_PLAN_COLUMNS && out.itemsize == 8 &&
                 out.len / 8 == plan.shape[0], InvalidArgumentError,
             "read_fields needs an int64 plan of shape (n, %d) and an int64 output of n items", RK_PLAN_COLUMNS);
    Py_ssize_t rows = plan.shape[0];
    const int64_t *p = plan.buf;
    for (Py_ssize_t r = 0; r < rows; r++) {
        const int64_t *row = p + r * RK_PLAN_COLUMNS;
        int64_t b = row[RK_PLAN_BUFFER], w = row[RK_PLAN_WIDTH], k = row[RK_PLAN_KIND];
        int bad = b < 0 || b >= nbuf || w < 1 || w > 8 || k < 0 || k > 3;
        for (int i = 0; !bad && i < w; i++)
            bad = row[RK_PLAN_OFFSETS + i] < 0 || row[RK_PLAN_OFFSETS + i] >= bufs[b].len;
        RK_CHECK(!bad, InvalidArgumentError, "field plan row %zd points outside its buffer", r);
    }
    RK_CHECK(!names || PyTuple_GET_SIZE(names) == rows, InvalidArgumentError,
             "read_fields needs one name per plan row (%zd), got %zd", rows, PyTuple_GET_SIZE(names));
    int64_t *dst = out.buf;
    for (Py_ssize_t r = 0; r < rows; r++) dst[r] = rk_decode_field(ptrs, p + r * RK_PLAN_COLUMNS);
    result = names ? values_by_name(names, p, dst, rows) : Py_NewRef(Py_None);
done:
    for (Py_ssize_t i = 0; i < got; i++) PyBuffer_Release(&bufs[i]);
    PyBuffer_Release(&plan);
    PyBuffer_Release(&out);
    Py_DECREF(seq);
    return result;
}

/* How items of a buffer format are tested for nonzero: 'i' byte by byte, 'f' or 'd' as floats; 0 if unknown. */
static char item_kind(const Py_buffer *b) {
    const char *f = b->format ? b->format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    if (f[0] && f[1]) return 0;
    if (*f == 'f' && b->itemsize == sizeof(float)) return 'f';
    if (*f == 'd' && b->itemsize == sizeof(double)) return 'd';
    return strchr("?bBhHiIlLqQ", *f) ? 'i' : 0;
}

static int item_pressed(const char *p, char kind, Py_ssize_t itemsize) {
    if (kind == 'f') return *(const float *)p != 0.0f;
    if (kind == 'd') return *(const double *)p != 0.0;
    for (Py_ssize_t k = 0; k < itemsize; k++)
        if (p[k]) return 1;
    return 0;
}

static PyObject *pack_buttons(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3 && nargs != 4) return PyErr_Format(PyExc_TypeError, "pack_buttons() takes (action, buttons, out[, table])");
    Py_ssize_t buttons = PyLong_AsSsize_t(args[1]);
    if (buttons == -1 && PyErr_Occurred()) return NULL;
    if (buttons < 1 || buttons > 16) return PyErr_Format(InvalidArgumentError, "buttons must be 1 to 16, got %zd", buttons);
    Py_buffer action = {0}, out = {0}, table = {0}; /* releasing a zeroed one is a no-op */
    PyObject *result = NULL;
    int with_table = nargs == 4 && args[3] != Py_None;
    if ((with_table && PyObject_GetBuffer(args[3], &table, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) ||
        PyObject_GetBuffer(args[0], &action, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0 ||
        PyObject_GetBuffer(args[2], &out, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0)
        goto done;
    const uint16_t *lookup = with_table ? table.buf : NULL;
    char kind = item_kind(&action);
    Py_ssize_t items = action.len / action.itemsize, players = items / buttons;
    if (with_table && (table.itemsize != 2 || table.len != ((Py_ssize_t)2 << buttons))) {
        PyErr_Format(InvalidArgumentError, "the table must hold 2**%zd uint16 masks, got %zd bytes", buttons,
                     table.len);
    } else if (!kind) { /* not a number format: the caller converts it itself */
        result = Py_NewRef(Py_False);
    } else if (out.itemsize != 2 || players * buttons != items || players > out.len / 2 || players > RK_MAX_PORTS) {
        PyErr_Format(InvalidArgumentError, "expected %zd buttons for each of at most %zd players, got %zd items", buttons,
                     out.len / out.itemsize < RK_MAX_PORTS ? out.len / out.itemsize : RK_MAX_PORTS, items);
    } else {
        uint16_t *masks = out.buf;
        const char *p = action.buf;
        for (Py_ssize_t player = 0; player < players; player++) {
            unsigned mask = 0;
            for (Py_ssize_t b = 0; b < buttons; b++, p += action.itemsize)
                mask |= (unsigned)item_pressed(p, kind, action.itemsize) << b;
            masks[player] = lookup ? lookup[mask] : (uint16_t)mask;
        }
        result = Py_NewRef(Py_True);
    }
done:
    PyBuffer_Release(&action);
    PyBuffer_Release(&out);
    PyBuffer_Release(&table);
    return result;
}

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
    int frames;
    if (!PyArg_ParseTuple(args, "OOi|O", &emus, &actions_obj, &frames, &screens)) return NULL;
    if (self->pid != getpid())
        return PyErr_Format(CoreError, "this runner was made in another process; make a new one after fork");
    if (frames < 0) return PyErr_Format(InvalidArgumentError, "frames must be 0 or more, got %d", frames);
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
            if (rk_py_get_screen(PySequence_Fast_GET_ITEM(screen_seq, i), &views[i], 0, 0)) goto done;
            tasks[i].screen = views[i].buf;
            tasks[i].screen_height = (unsigned)views[i].shape[0];
            tasks[i].screen_width = (unsigned)views[i].shape[1];
        }
        if (rk_py_enter(emu, 1)) goto done;
        claimed++;
        tasks[i].core = &emu->core;
        tasks[i].frames = frames;
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

static PyMethodDef runner_methods[] = {
    {"run", (PyCFunction)runner_run, METH_VARARGS,
     "run(emulators, actions, frames, screens=None): run them all; return whether each screen was converted."},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject RunnerType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "retrokit.native._host.Runner",
    .tp_basicsize = sizeof(RunnerObject),
    .tp_dealloc = (destructor)runner_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Runner(threads): worker threads that, with the caller, run several emulators' frames in one call.",
    .tp_methods = runner_methods,
    .tp_init = (initproc)runner_init,
    .tp_new = PyType_GenericNew,
};

static PyMethodDef module_methods[] = {
    {"read_fields", (PyCFunction)(void (*)(void))read_fields, METH_FASTCALL, "Decode RAM fields by a plan."},
    {"pack_buttons", (PyCFunction)(void (*)(void))pack_buttons, METH_FASTCALL,
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
