/*
 * retrokit.native._host: the CPython face of the libretro host.
 *
 * Data-only primitives: load, run frames, copy the screen, expose memory,
 * serialize. Arguments are checked before the core is touched, and every
 * failure raises; the GIL is released while frames run.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <string.h>

#include <unistd.h>

#include "core.h"
#include "fields.h"
#include "runner.h"
#include "video.h"

static PyObject *CoreError, *StateError, *InvalidArgumentError;

typedef struct {
    PyObject_HEAD
    rk_core core;
    PyObject *log;
    Py_ssize_t exports; /* live buffers onto the core's memory */
    int closed;
} EmulatorObject;

typedef struct {
    PyObject_HEAD
    EmulatorObject *owner;
    void *ptr;
    Py_ssize_t size;
} MemoryObject;

static PyTypeObject EmulatorType, MemoryType;

/* ---- helpers ----------------------------------------------------------------------------- */

static void flush_log(EmulatorObject *self) {
    rk_core *core = &self->core;
    for (int i = 0; i < core->n_log; i++) {
        if (self->log && self->log != Py_None) {
            PyObject *r = PyObject_CallFunction(self->log, "is", core->log[i].level, core->log[i].text);
            if (r) Py_DECREF(r);
            else PyErr_WriteUnraisable(self->log);
        }
        free(core->log[i].text);
    }
    core->n_log = 0;
}

/* Claim the emulator for this call; a second thread gets an error, not a race. */
static int enter(EmulatorObject *self, int need_game) {
    if (self->closed) {
        PyErr_SetString(CoreError, "this emulator is closed; make a new one");
        return -1;
    }
    if (need_game && !self->core.game_loaded) {
        PyErr_SetString(CoreError, "no game is loaded; call load_game first");
        return -1;
    }
    int expected = 0;
    if (!atomic_compare_exchange_strong(&self->core.busy, &expected, 1)) {
        PyErr_SetString(CoreError, "this emulator is running in another thread; use one emulator per thread");
        return -1;
    }
    return 0;
}

static void leave(EmulatorObject *self) {
    atomic_store(&self->core.busy, 0);
    flush_log(self);
}

static void really_close(EmulatorObject *self) {
    if (self->core.handle || self->core.system_dir) {
        rk_core_close(&self->core);
        flush_log(self);
    }
}

/* ---- memory buffers ------------------------------------------------------------------------- */

static int memory_getbuffer(MemoryObject *self, Py_buffer *view, int flags) {
    if (self->owner->closed && !self->owner->core.handle) {
        PyErr_SetString(CoreError, "the emulator behind this memory is closed");
        return -1;
    }
    if (PyBuffer_FillInfo(view, (PyObject *)self, self->ptr, self->size, 0, flags) < 0) return -1;
    self->owner->exports++;
    return 0;
}

static void memory_releasebuffer(MemoryObject *self, Py_buffer *view) { self->owner->exports--; }

static void memory_dealloc(MemoryObject *self) {
    Py_XDECREF(self->owner);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyBufferProcs memory_as_buffer = {(getbufferproc)memory_getbuffer, (releasebufferproc)memory_releasebuffer};

static PyTypeObject MemoryType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "retrokit.native._host.Memory",
    .tp_basicsize = sizeof(MemoryObject),
    .tp_dealloc = (destructor)memory_dealloc,
    .tp_as_buffer = &memory_as_buffer,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A region of a core's memory; it keeps its emulator alive.",
};

static PyObject *memory_view(EmulatorObject *self, void *ptr, size_t size) {
    MemoryObject *m = PyObject_New(MemoryObject, &MemoryType);
    if (!m) return NULL;
    Py_INCREF(self);
    m->owner = self;
    m->ptr = ptr;
    m->size = (Py_ssize_t)size;
    PyObject *view = PyMemoryView_FromObject((PyObject *)m);
    Py_DECREF(m);
    return view;
}

/* ---- Emulator: life cycle ---------------------------------------------------------------------- */

static int emulator_init(EmulatorObject *self, PyObject *args, PyObject *kwargs) {
    static char *kwlist[] = {"core_path", "system_dir", "save_dir", "options", "log", "ports", NULL};
    const char *path, *system_dir, *save_dir;
    PyObject *options = Py_None, *log = Py_None;
    int ports = 2;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "sss|OOi", kwlist, &path, &system_dir, &save_dir, &options,
                                     &log, &ports))
        return -1;
    if (self->core.handle) {
        PyErr_SetString(InvalidArgumentError, "Emulator.__init__ was called twice; make a new Emulator instead");
        return -1;
    }
    if (ports < 1 || ports > RK_MAX_PORTS) {
        PyErr_Format(InvalidArgumentError, "ports must be between 1 and %d, got %d", RK_MAX_PORTS, ports);
        return -1;
    }
    if (options != Py_None && !PyDict_Check(options)) {
        PyErr_Format(InvalidArgumentError, "options must be a dict of str to str, got %s", Py_TYPE(options)->tp_name);
        return -1;
    }
    if (log != Py_None && !PyCallable_Check(log)) {
        PyErr_SetString(InvalidArgumentError, "log must be a callable taking (level, text), or None");
        return -1;
    }
    self->core.n_ports = ports;
    if (options != Py_None) {
        PyObject *key, *value;
        Py_ssize_t pos = 0;
        while (PyDict_Next(options, &pos, &key, &value)) {
            if (!PyUnicode_Check(key) || !PyUnicode_Check(value)) {
                PyErr_SetString(InvalidArgumentError, "options must map str keys to str values");
                return -1;
            }
            rk_core_set_option(&self->core, PyUnicode_AsUTF8(key), PyUnicode_AsUTF8(value));
        }
    }
    Py_XINCREF(log);
    self->log = log;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = rk_core_open(&self->core, path, system_dir, save_dir);
    Py_END_ALLOW_THREADS
    flush_log(self);
    if (rc) {
        PyErr_SetString(CoreError, self->core.error);
        really_close(self);
        self->closed = 1;
        return -1;
    }
    return 0;
}

static void emulator_dealloc(EmulatorObject *self) {
    really_close(self);
    Py_XDECREF(self->log);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *emulator_close(EmulatorObject *self, PyObject *unused) {
    if (atomic_load(&self->core.busy)) {
        PyErr_SetString(CoreError, "cannot close an emulator that is running in another thread");
        return NULL;
    }
    self->closed = 1;
    /* Live memory views keep the core loaded until they are released. */
    if (self->exports == 0) really_close(self);
    Py_RETURN_NONE;
}

static PyObject *emulator_load_game(EmulatorObject *self, PyObject *args) {
    const char *path;
    Py_buffer data = {0};
    if (!PyArg_ParseTuple(args, "s|z*", &path, &data)) return NULL;
    if (self->core.game_loaded) {
        PyBuffer_Release(&data);
        PyErr_SetString(CoreError, "a game is already loaded; make a new Emulator for another game");
        return NULL;
    }
    if (enter(self, 0)) {
        PyBuffer_Release(&data);
        return NULL;
    }
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = rk_core_load_game(&self->core, path, data.buf, (size_t)data.len);
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&data);
    leave(self);
    if (rc) {
        PyErr_SetString(CoreError, self->core.error);
        return NULL;
    }
    Py_RETURN_NONE;
}

/* ---- Emulator: information ------------------------------------------------------------------------ */

static PyObject *emulator_system_info(EmulatorObject *self, PyObject *unused) {
    if (enter(self, 0)) return NULL;
    struct rk_retro_system_info info = {0};
    rk_enter(&self->core);
    self->core.api.get_system_info(&info);
    rk_leave();
    leave(self);
    return Py_BuildValue("{s:s,s:s,s:s,s:O,s:O}", "library_name", info.library_name ? info.library_name : "",
                         "library_version", info.library_version ? info.library_version : "", "valid_extensions",
                         info.valid_extensions ? info.valid_extensions : "", "need_fullpath",
                         info.need_fullpath ? Py_True : Py_False, "block_extract",
                         info.block_extract ? Py_True : Py_False);
}

static PyObject *emulator_av_info(EmulatorObject *self, PyObject *unused) {
    if (enter(self, 1)) return NULL;
    struct rk_retro_system_av_info av = self->core.av;
    leave(self);
    return Py_BuildValue("{s:d,s:d,s:I,s:I,s:I,s:I,s:d}", "fps", av.timing.fps, "sample_rate", av.timing.sample_rate,
                         "base_width", av.geometry.base_width, "base_height", av.geometry.base_height, "max_width",
                         av.geometry.max_width, "max_height", av.geometry.max_height, "aspect_ratio",
                         (double)av.geometry.aspect_ratio);
}

static PyObject *emulator_options(EmulatorObject *self, PyObject *unused) {
    if (self->closed) return PyErr_Format(CoreError, "this emulator is closed; make a new one");
    PyObject *result = PyDict_New();
    for (int i = 0; result && i < self->core.n_options; i++) {
        rk_option *o = &self->core.options[i];
        PyObject *allowed = PyTuple_New(o->n_allowed);
        for (int j = 0; allowed && j < o->n_allowed; j++)
            PyTuple_SET_ITEM(allowed, j, PyUnicode_FromString(o->allowed[j]));
        PyObject *entry = allowed ? Py_BuildValue("(ssN)", o->desc, o->value, allowed) : NULL;
        if (!entry || PyDict_SetItemString(result, o->key, entry) < 0) Py_CLEAR(result);
        Py_XDECREF(entry);
    }
    return result;
}

static PyObject *emulator_set_option(EmulatorObject *self, PyObject *args) {
    const char *key, *value;
    if (!PyArg_ParseTuple(args, "ss", &key, &value)) return NULL;
    if (self->closed) return PyErr_Format(CoreError, "this emulator is closed; make a new one");
    if (rk_core_set_option(&self->core, key, value)) {
        PyErr_SetString(InvalidArgumentError, self->core.error);
        return NULL;
    }
    Py_RETURN_NONE;
}

static PyObject *emulator_set_controller(EmulatorObject *self, PyObject *args) {
    unsigned port, device;
    if (!PyArg_ParseTuple(args, "II", &port, &device)) return NULL;
    if (port >= (unsigned)self->core.n_ports)
        return PyErr_Format(InvalidArgumentError, "port must be below %d, got %u", self->core.n_ports, port);
    if (enter(self, 1)) return NULL;
    rk_enter(&self->core);
    self->core.api.set_controller_port_device(port, device);
    rk_leave();
    leave(self);
    Py_RETURN_NONE;
}

/* ---- Emulator: running --------------------------------------------------------------------------------- */

static PyObject *emulator_set_sticky(EmulatorObject *self, PyObject *args) {
    double prob;
    unsigned long long seed;
    if (!PyArg_ParseTuple(args, "dK", &prob, &seed)) return NULL;
    if (!(prob >= 0.0 && prob <= 1.0))
        return PyErr_Format(InvalidArgumentError, "the sticky-action probability must be in [0, 1], got %R",
                            PyTuple_GET_ITEM(args, 0));
    rk_core_seed(&self->core, prob, seed);
    Py_RETURN_NONE;
}

static PyObject *emulator_forget_action(EmulatorObject *self, PyObject *unused) {
    self->core.have_held = 0;
    Py_RETURN_NONE;
}

static PyObject *emulator_run(EmulatorObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 2) return PyErr_Format(PyExc_TypeError, "run() takes (actions, frames), got %zd arguments", nargs);
    long frames = PyLong_AsLong(args[1]);
    if (frames == -1 && PyErr_Occurred()) return NULL;
    if (frames < 0) return PyErr_Format(InvalidArgumentError, "frames must be 0 or more, got %ld", frames);
    Py_buffer buf;
    if (PyObject_GetBuffer(args[0], &buf, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) return NULL;
    int ok = buf.itemsize == 2 && buf.format && (strcmp(buf.format, "H") == 0 || strcmp(buf.format, "=H") == 0 ||
                                                 strcmp(buf.format, "<H") == 0);
    Py_ssize_t n = ok ? buf.len / 2 : 0;
    if (!ok || n > self->core.n_ports) {
        PyErr_Format(InvalidArgumentError,
                     "actions must be a uint16 array of at most %d button masks (one per port), got format %s "
                     "with %zd bytes",
                     self->core.n_ports, buf.format ? buf.format : "B", buf.len);
        PyBuffer_Release(&buf);
        return NULL;
    }
    uint16_t actions[RK_MAX_PORTS] = {0};
    memcpy(actions, buf.buf, (size_t)n * 2);
    PyBuffer_Release(&buf);
    if (enter(self, 1)) return NULL;
    Py_BEGIN_ALLOW_THREADS
    rk_core_run(&self->core, actions, self->core.n_ports, (int)frames);
    Py_END_ALLOW_THREADS
    leave(self);
    Py_RETURN_NONE;
}

static PyObject *emulator_reset(EmulatorObject *self, PyObject *unused) {
    if (enter(self, 1)) return NULL;
    rk_enter(&self->core);
    self->core.api.reset();
    rk_leave();
    self->core.have_held = 0;
    leave(self);
    Py_RETURN_NONE;
}

/* ---- Emulator: screen, memory, audio ---------------------------------------------------------------- */

static PyObject *emulator_screen_shape(EmulatorObject *self, PyObject *unused) {
    if (enter(self, 1)) return NULL;
    unsigned w = self->core.frame_width, h = self->core.frame_height;
    if (!self->core.frame_data) {
        w = self->core.av.geometry.base_width;
        h = self->core.av.geometry.base_height;
    }
    leave(self);
    return Py_BuildValue("(II)", h, w);
}

static PyObject *emulator_screen(EmulatorObject *self, PyObject *out) {
    Py_buffer buf;
    if (PyObject_GetBuffer(out, &buf, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0) return NULL;
    if (enter(self, 1)) {
        PyBuffer_Release(&buf);
        return NULL;
    }
    rk_core *c = &self->core;
    unsigned w = c->frame_data ? c->frame_width : c->av.geometry.base_width;
    unsigned h = c->frame_data ? c->frame_height : c->av.geometry.base_height;
    int shape_ok = buf.ndim == 3 && buf.shape[0] == (Py_ssize_t)h && buf.shape[1] == (Py_ssize_t)w &&
                   buf.shape[2] == 3 && buf.itemsize == 1 && buf.format && strchr("Bc", buf.format[0]) &&
                   buf.format[1] == 0;
    if (!shape_ok) {
        leave(self);
        PyErr_Format(InvalidArgumentError,
                     "the screen buffer must be a C-contiguous uint8 array of shape (%u, %u, 3), got %zd dimensions "
                     "of %zd-byte items (format %s); make it with numpy.empty(emulator.screen_shape() + (3,), "
                     "numpy.uint8)",
                     h, w, (Py_ssize_t)buf.ndim, buf.itemsize, buf.format ? buf.format : "?");
        PyBuffer_Release(&buf);
        return NULL;
    }
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = rk_frame_to_rgb(c->frame_data, c->frame_pitch, w, h, c->pixel_format, buf.buf);
    Py_END_ALLOW_THREADS
    leave(self);
    PyBuffer_Release(&buf);
    if (rc) return PyErr_Format(CoreError, "the core uses pixel format %d, which retrokit cannot convert", c->pixel_format);
    Py_RETURN_NONE;
}

static PyObject *emulator_memory(EmulatorObject *self, PyObject *arg) {
    long kind = PyLong_AsLong(arg);
    if (kind == -1 && PyErr_Occurred()) return NULL;
    if (kind < 0 || kind > 255) return PyErr_Format(InvalidArgumentError, "memory kind must be 0..255, got %ld", kind);
    if (enter(self, 1)) return NULL;
    rk_enter(&self->core);
    void *ptr = self->core.api.get_memory_data((unsigned)kind);
    size_t size = self->core.api.get_memory_size((unsigned)kind);
    rk_leave();
    leave(self);
    if (!ptr || !size) Py_RETURN_NONE;
    return memory_view(self, ptr, size);
}

static PyObject *emulator_memory_maps(EmulatorObject *self, PyObject *unused) {
    if (enter(self, 1)) return NULL;
    leave(self);
    PyObject *list = PyList_New(0);
    for (int i = 0; list && i < self->core.n_maps; i++) {
        rk_memmap *m = &self->core.maps[i];
        PyObject *view = Py_None;
        Py_INCREF(view);
        if (m->ptr && m->len) {
            Py_DECREF(view);
            view = memory_view(self, (uint8_t *)m->ptr + m->offset, m->len);
            if (!view) {
                Py_CLEAR(list);
                break;
            }
        }
        PyObject *d = Py_BuildValue("{s:K,s:n,s:n,s:n,s:n,s:s,s:N}", "flags", (unsigned long long)m->flags, "start",
                                    (Py_ssize_t)m->start, "select", (Py_ssize_t)m->select, "disconnect",
                                    (Py_ssize_t)m->disconnect, "length", (Py_ssize_t)m->len, "addrspace",
                                    m->addrspace, "memory", view);
        if (!d || PyList_Append(list, d) < 0) Py_CLEAR(list);
        Py_XDECREF(d);
    }
    return list;
}

static PyObject *emulator_capture_audio(EmulatorObject *self, PyObject *arg) {
    int on = PyObject_IsTrue(arg);
    if (on < 0) return NULL;
    self->core.capture_audio = on;
    if (!on) self->core.audio_len = 0;
    Py_RETURN_NONE;
}

static PyObject *emulator_take_audio(EmulatorObject *self, PyObject *unused) {
    PyObject *out = PyBytes_FromStringAndSize((const char *)self->core.audio, (Py_ssize_t)(self->core.audio_len * 2));
    self->core.audio_len = 0;
    return out;
}

/* ---- Emulator: states ---------------------------------------------------------------------------------------- */

static PyObject *emulator_serialize_size(EmulatorObject *self, PyObject *unused) {
    if (enter(self, 1)) return NULL;
    rk_enter(&self->core);
    size_t size = self->core.api.serialize_size();
    rk_leave();
    leave(self);
    return PyLong_FromSize_t(size);
}

static PyObject *emulator_serialize(EmulatorObject *self, PyObject *unused) {
    if (enter(self, 1)) return NULL;
    rk_enter(&self->core);
    size_t size = self->core.api.serialize_size();
    rk_leave();
    PyObject *out = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)size);
    if (!out) {
        leave(self);
        return NULL;
    }
    bool ok;
    char *dst = PyBytes_AS_STRING(out);
    Py_BEGIN_ALLOW_THREADS
    rk_enter(&self->core);
    ok = self->core.api.serialize(dst, size);
    rk_leave();
    Py_END_ALLOW_THREADS
    leave(self);
    if (!ok) {
        Py_DECREF(out);
        return PyErr_Format(CoreError, "the core refused to serialize its state");
    }
    return out;
}

static PyObject *emulator_unserialize(EmulatorObject *self, PyObject *arg) {
    Py_buffer buf;
    if (PyObject_GetBuffer(arg, &buf, PyBUF_SIMPLE) < 0) return NULL;
    if (enter(self, 1)) {
        PyBuffer_Release(&buf);
        return NULL;
    }
    rk_enter(&self->core);
    size_t size = self->core.api.serialize_size();
    rk_leave();
    if ((size_t)buf.len != size) {
        leave(self);
        PyErr_Format(StateError,
                     "expected a state of %zu bytes for this core, got %zd bytes: the state is truncated, corrupt, "
                     "or was made by another core or core version; make it again with this core",
                     size, buf.len);
        PyBuffer_Release(&buf);
        return NULL;
    }
    bool ok;
    Py_BEGIN_ALLOW_THREADS
    rk_enter(&self->core);
    ok = self->core.api.unserialize(buf.buf, (size_t)buf.len);
    rk_leave();
    Py_END_ALLOW_THREADS
    self->core.have_held = 0;
    leave(self);
    PyBuffer_Release(&buf);
    if (!ok)
        return PyErr_Format(StateError, "the core refused the state (%zu bytes): it is corrupt or was made by "
                                        "another core; make it again with this core", size);
    Py_RETURN_NONE;
}

static PyObject *emulator_get_frame(EmulatorObject *self, void *closure) {
    return PyLong_FromUnsignedLongLong(self->core.frame);
}

static PyObject *emulator_get_pixel_format(EmulatorObject *self, void *closure) {
    return PyLong_FromLong(self->core.pixel_format);
}

static PyObject *emulator_get_stuck(EmulatorObject *self, void *closure) { return PyBool_FromLong(self->core.last_stuck); }

static PyObject *emulator_held(EmulatorObject *self, PyObject *unused) {
    PyObject *out = PyTuple_New(self->core.n_ports);
    for (int i = 0; out && i < self->core.n_ports; i++)
        PyTuple_SET_ITEM(out, i, PyLong_FromLong(self->core.have_held ? self->core.held[i] : 0));
    return out;
}

static PyObject *emulator_get_closed(EmulatorObject *self, void *closure) { return PyBool_FromLong(self->closed); }

static PyMethodDef emulator_methods[] = {
    {"load_game", (PyCFunction)emulator_load_game, METH_VARARGS, "Load a game from a path, with its bytes unless the core needs the path."},
    {"system_info", (PyCFunction)emulator_system_info, METH_NOARGS, "The core's name, version and extensions."},
    {"av_info", (PyCFunction)emulator_av_info, METH_NOARGS, "Frame rate, sample rate and geometry."},
    {"options", (PyCFunction)emulator_options, METH_NOARGS, "Core options: key -> (description, value, allowed)."},
    {"set_option", (PyCFunction)emulator_set_option, METH_VARARGS, "Set a core option."},
    {"set_controller", (PyCFunction)emulator_set_controller, METH_VARARGS, "Plug a device into a port."},
    {"set_sticky", (PyCFunction)emulator_set_sticky, METH_VARARGS, "Set the sticky-action probability and seed the RNG."},
    {"forget_action", (PyCFunction)emulator_forget_action, METH_NOARGS, "Apply the next action from its first frame."},
    {"held", (PyCFunction)emulator_held, METH_NOARGS, "The buttons of the last frame run, one mask per port."},
    {"run", (PyCFunction)(void (*)(void))emulator_run, METH_FASTCALL, "Run frames with one button mask per port."},
    {"reset", (PyCFunction)emulator_reset, METH_NOARGS, "Hard-reset the console."},
    {"screen_shape", (PyCFunction)emulator_screen_shape, METH_NOARGS, "(height, width) of the last frame."},
    {"screen", (PyCFunction)emulator_screen, METH_O, "Write the last frame as RGB into a uint8 array."},
    {"memory", (PyCFunction)emulator_memory, METH_O, "A writable zero-copy view of a core memory, or None."},
    {"memory_maps", (PyCFunction)emulator_memory_maps, METH_NOARGS, "The core's memory descriptors, with views."},
    {"capture_audio", (PyCFunction)emulator_capture_audio, METH_O, "Start or stop keeping audio samples."},
    {"take_audio", (PyCFunction)emulator_take_audio, METH_NOARGS, "Return and clear the captured int16 stereo samples."},
    {"serialize_size", (PyCFunction)emulator_serialize_size, METH_NOARGS, "The size of a serialized state."},
    {"serialize", (PyCFunction)emulator_serialize, METH_NOARGS, "The core's state as bytes."},
    {"unserialize", (PyCFunction)emulator_unserialize, METH_O, "Restore a state made by serialize."},
    {"close", (PyCFunction)emulator_close, METH_NOARGS, "Unload the game and the core."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef emulator_getset[] = {
    {"frame", (getter)emulator_get_frame, NULL, "Frames run since the core was loaded.", NULL},
    {"pixel_format", (getter)emulator_get_pixel_format, NULL, "The core's libretro pixel format.", NULL},
    {"closed", (getter)emulator_get_closed, NULL, "Whether close() was called.", NULL},
    {"stuck", (getter)emulator_get_stuck, NULL, "Whether the last run's first frame kept the previous buttons.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject EmulatorType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "retrokit.native._host.Emulator",
    .tp_basicsize = sizeof(EmulatorObject),
    .tp_dealloc = (destructor)emulator_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "One libretro core, privately loaded, with at most one game.",
    .tp_methods = emulator_methods,
    .tp_getset = emulator_getset,
    .tp_init = (initproc)emulator_init,
    .tp_new = PyType_GenericNew,
};


/* ---- Runner: several emulators' frames in one call ------------------------------------------------ */

typedef struct {
    PyObject_HEAD
    rk_runner runner;
    int threads;
    pid_t pid;
    atomic_int busy;
} RunnerObject;

static int runner_init(RunnerObject *self, PyObject *args, PyObject *kwargs) {
    static char *kwlist[] = {"threads", NULL};
    int threads;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "i", kwlist, &threads)) return -1;
    if (self->runner.workers) {
        PyErr_SetString(InvalidArgumentError, "Runner.__init__ was called twice; make a new Runner instead");
        return -1;
    }
    if (threads < 0 || threads > 256) {
        PyErr_Format(InvalidArgumentError, "threads must be 0 to 256, got %d", threads);
        return -1;
    }
    if (rk_runner_init(&self->runner, threads)) {
        PyErr_SetString(CoreError, "cannot start the runner's threads");
        return -1;
    }
    self->threads = threads;
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
    PyObject *seq = PySequence_Fast(emus, "emulators must be a sequence of Emulator objects");
    if (!seq) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    PyObject *screen_seq = NULL, *result = NULL;
    rk_task *tasks = NULL;
    Py_buffer actions = {0}, *views = NULL;
    Py_ssize_t claimed = 0, viewed = 0;
    int runner_claimed = 0, expected = 0;
    if (n > self->threads + 1) {
        PyErr_Format(InvalidArgumentError, "this runner has %d threads, so at most %d emulators, got %zd",
                     self->threads, self->threads + 1, n);
        goto done;
    }
    if (!atomic_compare_exchange_strong(&self->busy, &expected, 1)) {
        PyErr_SetString(CoreError, "this runner is running in another thread; use one runner per thread");
        goto done;
    }
    runner_claimed = 1;
    if (PyObject_GetBuffer(actions_obj, &actions, PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0) goto done;
    tasks = calloc((size_t)(n > 0 ? n : 1), sizeof(rk_task));
    views = calloc((size_t)(n > 0 ? n : 1), sizeof(Py_buffer));
    if (!tasks || !views) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *item = PySequence_Fast_GET_ITEM(seq, i);
        if (!Py_IS_TYPE(item, &EmulatorType)) {
            PyErr_Format(InvalidArgumentError, "emulator %zd is a %s, not a native Emulator", i, Py_TYPE(item)->tp_name);
            goto done;
        }
    }
    int ports = n > 0 ? ((EmulatorObject *)PySequence_Fast_GET_ITEM(seq, 0))->core.n_ports : 0;
    if (actions.itemsize != 2 || actions.ndim != 2 || actions.shape[0] != n || actions.shape[1] != ports) {
        PyErr_Format(InvalidArgumentError, "actions must be a uint16 array of shape (%zd, %d): one mask per port "
                     "per emulator", n, ports);
        goto done;
    }
    if (screens != Py_None) {
        screen_seq = PySequence_Fast(screens, "screens must be a sequence of buffers, or None");
        if (!screen_seq) goto done;
        if (PySequence_Fast_GET_SIZE(screen_seq) != n) {
            PyErr_Format(InvalidArgumentError, "expected %zd screen buffers, got %zd", n, PySequence_Fast_GET_SIZE(screen_seq));
            goto done;
        }
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        EmulatorObject *emu = (EmulatorObject *)PySequence_Fast_GET_ITEM(seq, i);
        if (emu->core.n_ports != ports) {
            PyErr_Format(InvalidArgumentError, "every emulator must have %d ports; emulator %zd has %d", ports, i,
                         emu->core.n_ports);
            goto done;
        }
        if (screen_seq) {
            PyObject *buf = PySequence_Fast_GET_ITEM(screen_seq, i);
            if (PyObject_GetBuffer(buf, &views[i], PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0)
                goto done;
            viewed++;
            if (views[i].ndim != 3 || views[i].shape[2] != 3 || views[i].itemsize != 1) {
                PyErr_Format(InvalidArgumentError, "screen buffer %zd must be a uint8 array of shape (height, width, 3)", i);
                goto done;
            }
            tasks[i].screen = views[i].buf;
            tasks[i].screen_height = (unsigned)views[i].shape[0];
            tasks[i].screen_width = (unsigned)views[i].shape[1];
        }
        if (enter(emu, 1)) goto done;
        claimed++;
        tasks[i].core = &emu->core;
        tasks[i].actions = (const uint16_t *)actions.buf + i * ports;
        tasks[i].frames = frames;
    }
    Py_BEGIN_ALLOW_THREADS
    rk_runner_run(&self->runner, tasks, (int)n);
    Py_END_ALLOW_THREADS
    result = PyTuple_New(n);
    for (Py_ssize_t i = 0; result && i < n; i++) PyTuple_SET_ITEM(result, i, PyBool_FromLong(tasks[i].converted));
done:
    for (Py_ssize_t i = 0; i < claimed; i++) leave((EmulatorObject *)PySequence_Fast_GET_ITEM(seq, i));
    for (Py_ssize_t i = 0; i < viewed; i++) PyBuffer_Release(&views[i]);
    if (actions.obj) PyBuffer_Release(&actions);
    if (runner_claimed) atomic_store(&self->busy, 0);
    free(tasks);
    free(views);
    Py_XDECREF(screen_seq);
    Py_DECREF(seq);
    return result;
}

static PyMethodDef runner_methods[] = {
    {"run", (PyCFunction)runner_run, METH_VARARGS,
     "run(emulators, actions, frames, screens=None): run every emulator's frames at once, each on its own "
     "thread, and convert each screen into its buffer; return whether each screen was converted."},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject RunnerType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "retrokit.native._host.Runner",
    .tp_basicsize = sizeof(RunnerObject),
    .tp_dealloc = (destructor)runner_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A pool of native threads that run several emulators' frames in one call.",
    .tp_methods = runner_methods,
    .tp_init = (initproc)runner_init,
    .tp_new = PyType_GenericNew,
};

/* ---- read_fields ------------------------------------------------------------------------------------------------------ */

#define RK_MAX_BUFFERS 16

static PyObject *host_read_fields(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3) return PyErr_Format(PyExc_TypeError, "read_fields() takes (buffers, plan, out)");
    PyObject *seq = PySequence_Fast(args[0], "buffers must be a sequence of buffers");
    if (!seq) return NULL;
    Py_ssize_t nbuf = PySequence_Fast_GET_SIZE(seq);
    if (nbuf > RK_MAX_BUFFERS) {
        Py_DECREF(seq);
        return PyErr_Format(InvalidArgumentError, "at most %d buffers, got %zd", RK_MAX_BUFFERS, nbuf);
    }
    Py_buffer bufs[RK_MAX_BUFFERS], plan, out;
    const uint8_t *ptrs[RK_MAX_BUFFERS];
    Py_ssize_t got = 0;
    PyObject *result = NULL;
    int have_plan = 0, have_out = 0;
    for (; got < nbuf; got++) {
        if (PyObject_GetBuffer(PySequence_Fast_GET_ITEM(seq, got), &bufs[got], PyBUF_SIMPLE) < 0) goto done;
        ptrs[got] = bufs[got].buf;
    }
    if (PyObject_GetBuffer(args[1], &plan, PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0) goto done;
    have_plan = 1;
    if (PyObject_GetBuffer(args[2], &out, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) goto done;
    have_out = 1;
    if (plan.itemsize != 8 || plan.ndim != 2 || plan.shape[1] != RK_PLAN_COLUMNS || out.itemsize != 8 ||
        out.len / 8 != plan.shape[0]) {
        PyErr_Format(InvalidArgumentError,
                     "read_fields needs an int64 plan of shape (n, %d) and an int64 output of n items", RK_PLAN_COLUMNS);
        goto done;
    }
    Py_ssize_t rows = plan.shape[0];
    const int64_t *p = plan.buf;
    for (Py_ssize_t r = 0; r < rows; r++) {
        const int64_t *row = p + r * RK_PLAN_COLUMNS;
        int64_t b = row[RK_PLAN_BUFFER], w = row[RK_PLAN_WIDTH], k = row[RK_PLAN_KIND];
        int bad = b < 0 || b >= nbuf || w < 1 || w > 8 || k < 0 || k > 3;
        for (int i = 0; !bad && i < w; i++)
            bad = row[RK_PLAN_OFFSETS + i] < 0 || row[RK_PLAN_OFFSETS + i] >= bufs[b].len;
        if (bad) {
            PyErr_Format(InvalidArgumentError, "field plan row %zd points outside its buffer", r);
            goto done;
        }
    }
    int64_t *dst = out.buf;
    for (Py_ssize_t r = 0; r < rows; r++) dst[r] = rk_decode_field(ptrs, p + r * RK_PLAN_COLUMNS);
    result = Py_None;
    Py_INCREF(result);
done:
    for (Py_ssize_t i = 0; i < got; i++) PyBuffer_Release(&bufs[i]);
    if (have_plan) PyBuffer_Release(&plan);
    if (have_out) PyBuffer_Release(&out);
    Py_DECREF(seq);
    return result;
}

static PyObject *host_convert_frame(PyObject *module, PyObject *args) {
    Py_buffer src, dst;
    unsigned width, height;
    Py_ssize_t pitch;
    int format;
    PyObject *out;
    if (!PyArg_ParseTuple(args, "y*IIniO", &src, &width, &height, &pitch, &format, &out)) return NULL;
    int bytes_per_pixel = format == RK_RETRO_PIXEL_FORMAT_XRGB8888 ? 4 : 2;
    if (format < 0 || format > 2) {
        PyBuffer_Release(&src);
        return PyErr_Format(InvalidArgumentError, "format must be 0 (0RGB1555), 1 (XRGB8888) or 2 (RGB565), got %d", format);
    }
    if (pitch < (Py_ssize_t)width * bytes_per_pixel || (height > 0 && src.len < pitch * (Py_ssize_t)(height - 1) + (Py_ssize_t)width * bytes_per_pixel)) {
        PyBuffer_Release(&src);
        return PyErr_Format(InvalidArgumentError, "a %ux%u frame with rows %zd bytes apart needs more than the %zd bytes given",
                            width, height, pitch, src.len);
    }
    if (PyObject_GetBuffer(out, &dst, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) {
        PyBuffer_Release(&src);
        return NULL;
    }
    if (dst.len != (Py_ssize_t)width * height * 3) {
        PyBuffer_Release(&src);
        PyBuffer_Release(&dst);
        return PyErr_Format(InvalidArgumentError, "the output must hold %u x %u x 3 bytes, got %zd", height, width, dst.len);
    }
    rk_frame_to_rgb(src.buf, (size_t)pitch, width, height, format, dst.buf);
    PyBuffer_Release(&src);
    PyBuffer_Release(&dst);
    Py_RETURN_NONE;
}

static PyMethodDef module_methods[] = {
    {"read_fields", (PyCFunction)(void (*)(void))host_read_fields, METH_FASTCALL, "Decode RAM fields by a plan."},
    {"convert_frame", (PyCFunction)host_convert_frame, METH_VARARGS,
     "convert_frame(data, width, height, pitch, format, out): a frame in a libretro pixel format to RGB."},
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
