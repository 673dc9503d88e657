/*
 * The Emulator type of retrokit.native._host: loading, information, running.
 * What it hands out (screen, memory, audio, states) is in host_data.c.
 *
 * Arguments are checked before the core is touched, and every failure
 * raises; the GIL is released while frames run.
 */
#include "host.h"

#include <string.h>

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
int rk_py_enter(EmulatorObject *self, int need_game) {
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

void rk_py_leave(EmulatorObject *self) {
    atomic_store(&self->core.busy, 0);
    flush_log(self);
}

void rk_py_really_close(EmulatorObject *self) {
    if (self->core.handle || self->core.system_dir) {
        rk_core_close(&self->core);
        flush_log(self);
    }
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
        rk_py_really_close(self);
        self->closed = 1;
        return -1;
    }
    return 0;
}

static void emulator_dealloc(EmulatorObject *self) {
    rk_py_really_close(self);
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
    if (self->exports == 0) rk_py_really_close(self);
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
    if (rk_py_enter(self, 0)) {
        PyBuffer_Release(&data);
        return NULL;
    }
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = rk_core_load_game(&self->core, path, data.buf, (size_t)data.len);
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&data);
    rk_py_leave(self);
    if (rc) {
        PyErr_SetString(CoreError, self->core.error);
        return NULL;
    }
    Py_RETURN_NONE;
}

/* ---- Emulator: information ------------------------------------------------------------------------ */

static PyObject *emulator_system_info(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 0)) return NULL;
    struct rk_retro_system_info info = {0};
    rk_enter(&self->core);
    self->core.api.get_system_info(&info);
    rk_leave();
    rk_py_leave(self);
    return Py_BuildValue("{s:s,s:s,s:s,s:O,s:O}", "library_name", info.library_name ? info.library_name : "",
                         "library_version", info.library_version ? info.library_version : "", "valid_extensions",
                         info.valid_extensions ? info.valid_extensions : "", "need_fullpath",
                         info.need_fullpath ? Py_True : Py_False, "block_extract",
                         info.block_extract ? Py_True : Py_False);
}

static PyObject *emulator_av_info(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    struct rk_retro_system_av_info av = self->core.av;
    rk_py_leave(self);
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
    if (rk_py_enter(self, 1)) return NULL;
    rk_enter(&self->core);
    self->core.api.set_controller_port_device(port, device);
    rk_leave();
    rk_py_leave(self);
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

static PyObject *emulator_set_video_frames(EmulatorObject *self, PyObject *arg) {
    long mode = PyLong_AsLong(arg);
    if (mode == -1 && PyErr_Occurred()) return NULL;
    if (mode < RK_VIDEO_ALL || mode > RK_VIDEO_NONE)
        return PyErr_Format(InvalidArgumentError, "video frames must be VIDEO_ALL, VIDEO_LAST or VIDEO_NONE, got %ld", mode);
    self->core.video_frames = (int)mode;
    Py_RETURN_NONE;
}

static PyObject *emulator_forget_action(EmulatorObject *self, PyObject *unused) {
    self->core.have_held = 0;
    Py_RETURN_NONE;
}

static PyObject *emulator_run(EmulatorObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 2 && nargs != 3)
        return PyErr_Format(PyExc_TypeError, "run() takes (actions, frames[, screen]), got %zd arguments", nargs);
    long frames = PyLong_AsLong(args[1]);
    if (frames == -1 && PyErr_Occurred()) return NULL;
    if (frames < 0) return PyErr_Format(InvalidArgumentError, "frames must be 0 or more, got %ld", frames);
    Py_buffer buf, screen = {0};
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
    int want_screen = nargs == 3 && args[2] != Py_None;
    if (want_screen) {
        if (PyObject_GetBuffer(args[2], &screen, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_ND | PyBUF_C_CONTIGUOUS) < 0)
            return NULL;
        if (screen.ndim != 3 || screen.shape[2] != 3 || screen.itemsize != 1) {
            PyBuffer_Release(&screen);
            return PyErr_Format(InvalidArgumentError, "the screen buffer must be a uint8 array of shape (height, width, 3)");
        }
    }
    if (rk_py_enter(self, 1)) {
        if (want_screen) PyBuffer_Release(&screen);
        return NULL;
    }
    int converted = 0;
    rk_core *c = &self->core;
    Py_BEGIN_ALLOW_THREADS
    rk_core_run(c, actions, c->n_ports, (int)frames);
    /* Convert while the frame is still in the cache, if it fits the buffer. */
    if (want_screen)
        converted = rk_core_screen_into(c, screen.buf, (unsigned)screen.shape[1], (unsigned)screen.shape[0]);
    Py_END_ALLOW_THREADS
    rk_py_leave(self);
    if (want_screen) {
        PyBuffer_Release(&screen);
        return PyBool_FromLong(converted);
    }
    Py_RETURN_NONE;
}

static PyObject *emulator_reset(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_enter(&self->core);
    self->core.api.reset();
    rk_leave();
    self->core.have_held = 0;
    rk_py_leave(self);
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

static PyObject *emulator_get_av_asked(EmulatorObject *self, void *closure) {
    return PyLong_FromUnsignedLongLong(self->core.av_asked);
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
    {"set_video_frames", (PyCFunction)emulator_set_video_frames, METH_O,
     "Which frames of each run the core is told to draw: VIDEO_ALL, VIDEO_LAST or VIDEO_NONE."},
    {"forget_action", (PyCFunction)emulator_forget_action, METH_NOARGS, "Apply the next action from its first frame."},
    {"held", (PyCFunction)emulator_held, METH_NOARGS, "The buttons of the last frame run, one mask per port."},
    {"run", (PyCFunction)(void (*)(void))emulator_run, METH_FASTCALL,
     "run(actions, frames[, screen]): run frames with one button mask per port; with a screen buffer, convert "
     "the last frame into it and return whether it fitted."},
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
    {"av_asked", (getter)emulator_get_av_asked, NULL, "How often the core asked whether video and audio are wanted.",
     NULL},
    {"closed", (getter)emulator_get_closed, NULL, "Whether close() was called.", NULL},
    {"stuck", (getter)emulator_get_stuck, NULL, "Whether the last run's first frame kept the previous buttons.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject EmulatorType = {
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


