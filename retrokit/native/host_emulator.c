/*
 * The Emulator type of retrokit.native._host: loading, information, running,
 * and what it hands out: its screen as RGB and audio; its memory is
 * host_memory.c's, its states host_state.c's.
 *
 * Arguments are checked before the core is touched, and every failure
 * raises; the GIL is released while frames run.
 */
#include "host.h"

#include <limits.h>
#include <string.h>

#include "video.h"

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
    int expected = 0;
    const char *error = NULL;
    if (self->closed) error = "this emulator is closed; make a new one";
    else if (need_game && !self->core.game_loaded) error = "no game is loaded; call load_game first";
    else if (!atomic_compare_exchange_strong(&self->core.busy, &expected, 1))
        error = "this emulator is running in another thread; use one emulator per thread";
    if (error) PyErr_SetString(CoreError, error);
    return error ? -1 : 0;
}

void rk_py_leave(EmulatorObject *self) {
    atomic_store(&self->core.busy, 0);
    flush_log(self);
}

static void really_close(EmulatorObject *self) {
    if (!self->core.handle && !self->core.system_dir) return;
    rk_core_close(&self->core);
    flush_log(self);
}

static int emulator_init(EmulatorObject *self, PyObject *args, PyObject *kwargs) {
    static char *kwlist[] = {"core_path", "system_dir", "save_dir", "options", "log", "ports", NULL};
    const char *path, *system_dir, *save_dir;
    PyObject *options = Py_None, *log = Py_None, *key, *value;
    Py_ssize_t pos = 0;
    int ports = 2;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "sss|OOi", kwlist, &path, &system_dir, &save_dir, &options,
                                     &log, &ports))
        return -1;
    if (self->core.handle)
        return rk_py_fail(InvalidArgumentError, "Emulator.__init__ was called twice; make a new Emulator instead");
    if (ports < 1 || ports > RK_MAX_PORTS)
        return rk_py_fail(InvalidArgumentError, "ports must be between 1 and %d, got %d", RK_MAX_PORTS, ports);
    if (options != Py_None && !PyDict_Check(options))
        return rk_py_fail(InvalidArgumentError, "options must be a dict of str to str, got %s",
                          Py_TYPE(options)->tp_name);
    if (log != Py_None && !PyCallable_Check(log))
        return rk_py_fail(InvalidArgumentError, "log must be a callable taking (level, text), or None");
    self->core.n_ports = ports;
    while (options != Py_None && PyDict_Next(options, &pos, &key, &value)) {
        if (!PyUnicode_Check(key) || !PyUnicode_Check(value))
            return rk_py_fail(InvalidArgumentError, "options must map str keys to str values");
        const char *k = PyUnicode_AsUTF8(key), *v = k ? PyUnicode_AsUTF8(value) : NULL;
        if (!v) return -1; /* a str UTF-8 cannot hold (a lone surrogate): UnicodeEncodeError */
        rk_core_set_option(&self->core, k, v);
    }
    self->log = Py_NewRef(log);
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = rk_core_open(&self->core, path, system_dir, save_dir);
    Py_END_ALLOW_THREADS
    flush_log(self);
    if (!rc) return 0;
    self->closed = 1;
    really_close(self); /* before raising: it may call the log callback */
    return rk_py_fail(CoreError, "%s", self->core.error);
}

static void emulator_dealloc(EmulatorObject *self) {
    really_close(self);
    Py_XDECREF(self->log);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *emulator_close(EmulatorObject *self, PyObject *unused) {
    if (atomic_load(&self->core.busy))
        return PyErr_Format(CoreError, "cannot close an emulator that is running in another thread");
    self->closed = 1;
    /* Live memory views keep the core loaded until they are released. */
    if (self->exports == 0) really_close(self);
    Py_RETURN_NONE;
}

static PyObject *emulator_load_game(EmulatorObject *self, PyObject *args) {
    const char *path;
    Py_buffer data = {0};
    int keep = 0;
    if (self->core.game_loaded || self->core.game_path)
        return PyErr_Format(CoreError, "a game is already loaded; make a new Emulator for another game");
    if (!PyArg_ParseTuple(args, "s|z*p", &path, &data, &keep)) return NULL;
    if (rk_py_enter(self, 0)) return rk_py_release(&data, NULL);
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = rk_core_load_game(&self->core, path, data.buf, (size_t)data.len, keep);
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&data);
    rk_py_leave(self);
    if (rc) return PyErr_Format(CoreError, "%s", self->core.error);
    Py_RETURN_NONE;
}

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
        for (int j = 0; allowed && j < o->n_allowed; j++) {
            PyObject *value = PyUnicode_FromString(o->allowed[j]); /* fails if the core's text is not UTF-8 */
            if (value) PyTuple_SET_ITEM(allowed, j, value);
            else Py_CLEAR(allowed);
        }
        PyObject *entry = Py_BuildValue("(ssN)", o->desc, o->value, allowed); /* N passes a NULL's error on */
        if (!entry || PyDict_SetItemString(result, o->key, entry) < 0) Py_CLEAR(result);
        Py_XDECREF(entry);
    }
    return result;
}

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

static PyObject *emulator_set_preprocess(EmulatorObject *self, PyObject *arg) {
    rk_prep_spec spec = {0};
    rk_prep *prep = NULL;
    if (arg != Py_None) {
        if (!PyArg_ParseTuple(arg, "IIIIIIIIiiiIi;the preprocessing must be a tuple of 13 integers",
                              &spec.screen_height, &spec.screen_width, &spec.top, &spec.bottom, &spec.left,
                              &spec.right, &spec.height, &spec.width, &spec.method, &spec.gray, &spec.max_pool,
                              &spec.stack, &spec.channels_first))
            return NULL;
        char error[256];
        if (!(prep = rk_prep_new(&spec, error, sizeof error))) return PyErr_Format(InvalidArgumentError, "%s", error);
    }
    if (rk_py_enter(self, 0)) {
        rk_prep_free(prep);
        return NULL;
    }
    rk_prep_free(self->core.prep);
    self->core.prep = prep;
    rk_py_leave(self);
    Py_RETURN_NONE;
}

static PyObject *emulator_observe(EmulatorObject *self, PyObject *args) {
    PyObject *out, *frame_obj = Py_None;
    int restart = 0;
    if (!PyArg_ParseTuple(args, "O|pO", &out, &restart, &frame_obj)) return NULL;
    if (!self->core.prep) return PyErr_Format(InvalidArgumentError, "observe() needs a preprocessing; call set_preprocess first");
    Py_buffer obs = {0}, frame = {0};
    if (rk_py_get_obs(self, out, &obs)) return NULL;
    if (frame_obj != Py_None && rk_py_get_screen(frame_obj, &frame, 0, 0)) return rk_py_release(&obs, NULL);
    if (rk_py_enter(self, 1)) {
        PyBuffer_Release(&frame);
        return rk_py_release(&obs, NULL);
    }
    rk_core *c = &self->core;
    Py_BEGIN_ALLOW_THREADS
    if (restart) rk_prep_restart(c->prep);
    if (frame.buf)
        rk_prep_observe_rgb(c->prep, frame.buf, (unsigned)frame.shape[1], (unsigned)frame.shape[0], obs.buf);
    else
        rk_prep_observe(c->prep, c, obs.buf);
    Py_END_ALLOW_THREADS
    rk_py_leave(self);
    PyBuffer_Release(&frame);
    return rk_py_release(&obs, Py_NewRef(Py_None));
}

static PyObject *emulator_forget_action(EmulatorObject *self, PyObject *unused) {
    self->core.have_held = 0;
    Py_RETURN_NONE;
}

static PyObject *emulator_run(EmulatorObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs < 2 || nargs > 4)
        return PyErr_Format(PyExc_TypeError, "run() takes (actions, frames[, screen[, after]]), got %zd arguments",
                            nargs);
    long frames = PyLong_AsLong(args[1]), after = nargs == 4 ? PyLong_AsLong(args[3]) : 0;
    if ((frames == -1 || after == -1) && PyErr_Occurred()) return NULL;
    if (frames < 0 || frames > INT_MAX) /* the core loop counts in an int: never wrap to 0 or a few frames */
        return PyErr_Format(InvalidArgumentError, "frames must be 0 or more and at most %d, got %ld", INT_MAX, frames);
    if (after < 0 || after > INT_MAX)
        return PyErr_Format(InvalidArgumentError, "after must be 0 or more and at most %d, got %ld", INT_MAX, after);
    Py_buffer buf, screen = {0};
    if (PyObject_GetBuffer(args[0], &buf, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) return NULL;
    const char *f = buf.format ? buf.format : "B";
    Py_ssize_t n = buf.len / 2;
    if (buf.itemsize != 2 || (strcmp(f, "H") && strcmp(f, "=H") && strcmp(f, "<H")) || n > self->core.n_ports)
        return rk_py_release(&buf, PyErr_Format(InvalidArgumentError,
                                                "actions must be a uint16 array of at most %d button masks (one per "
                                                "port), got format %s with %zd bytes", self->core.n_ports, f, buf.len));
    uint16_t actions[RK_MAX_PORTS] = {0};
    memcpy(actions, buf.buf, (size_t)n * 2);
    PyBuffer_Release(&buf);
    int want_screen = nargs >= 3 && args[2] != Py_None;
    if (want_screen && rk_py_get_obs(self, args[2], &screen)) return NULL;
    if (rk_py_enter(self, 1)) return rk_py_release(&screen, NULL);
    int converted = 0;
    rk_core *c = &self->core;
    Py_BEGIN_ALLOW_THREADS
    rk_core_run(c, actions, c->n_ports, (int)frames, (int)after);
    /* Convert while the frame is still in the cache, if it fits the buffer. */
    if (want_screen)
        converted = rk_core_screen_into(c, screen.buf, screen.ndim == 3 ? (unsigned)screen.shape[1] : 0,
                                        screen.ndim == 3 ? (unsigned)screen.shape[0] : 0);
    Py_END_ALLOW_THREADS
    rk_py_leave(self);
    return rk_py_release(&screen, want_screen ? PyBool_FromLong(converted) : Py_NewRef(Py_None));
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

static PyObject *emulator_get_frame(EmulatorObject *self, void *c) { return PyLong_FromUnsignedLongLong(self->core.frame); }
static PyObject *emulator_get_stuck(EmulatorObject *self, void *c) { return PyBool_FromLong(self->core.last_stuck); }

static PyObject *emulator_held(EmulatorObject *self, PyObject *unused) {
    PyObject *out = PyTuple_New(self->core.n_ports);
    for (int i = 0; out && i < self->core.n_ports; i++)
        PyTuple_SET_ITEM(out, i, PyLong_FromLong(self->core.have_held ? self->core.held[i] : 0));
    return out;
}

static PyObject *emulator_get_av_asked(EmulatorObject *self, void *closure) {
    return PyLong_FromUnsignedLongLong(self->core.av_asked);
}

static PyObject *emulator_get_av_drawn(EmulatorObject *self, void *closure) {
    return PyLong_FromUnsignedLongLong(self->core.av_drawn);
}

static PyObject *emulator_screen_shape(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_core *c = &self->core; /* before the first frame, the size the core announced; after a reload, the last */
    unsigned w = c->frame_width ? c->frame_width : c->av.geometry.base_width;
    unsigned h = c->frame_width ? c->frame_height : c->av.geometry.base_height;
    rk_py_leave(self);
    return Py_BuildValue("(II)", h, w);
}

static PyObject *emulator_screen(EmulatorObject *self, PyObject *out) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_core *c = &self->core;
    unsigned w = c->frame_width ? c->frame_width : c->av.geometry.base_width;
    unsigned h = c->frame_width ? c->frame_height : c->av.geometry.base_height;
    Py_buffer buf;
    if (rk_py_get_screen(out, &buf, h, w)) {
        rk_py_leave(self);
        return NULL;
    }
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = rk_frame_to_rgb(c->frame_data, c->frame_pitch, w, h, c->pixel_format, buf.buf);
    Py_END_ALLOW_THREADS
    rk_py_leave(self);
    if (rc) PyErr_Format(CoreError, "the core uses pixel format %d, which retrokit cannot convert", c->pixel_format);
    return rk_py_release(&buf, rc ? NULL : Py_NewRef(Py_None));
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

static PyMethodDef emulator_methods[] = {
    {"load_game", (PyCFunction)emulator_load_game, METH_VARARGS,
     "load_game(path, data=None, keep=False): load a game from a path, with its bytes unless the core needs the "
     "path; keep: hold a copy, so that reload() can load it again."},
    {"system_info", (PyCFunction)emulator_system_info, METH_NOARGS, "The core's name, version and extensions."},
    {"av_info", (PyCFunction)emulator_av_info, METH_NOARGS, "Frame rate, sample rate and geometry."},
    {"options", (PyCFunction)emulator_options, METH_NOARGS, "Core options: key -> (description, value, allowed)."},
    {"set_sticky", (PyCFunction)emulator_set_sticky, METH_VARARGS, "Set the sticky-action probability and seed the RNG."},
    {"set_video_frames", (PyCFunction)emulator_set_video_frames, METH_O,
     "Which frames of each run the core is told to draw: VIDEO_ALL, VIDEO_LAST or VIDEO_NONE."},
    {"set_preprocess", (PyCFunction)emulator_set_preprocess, METH_O,
     "Make observations through a native preprocessing (a tuple of 13 integers, see _host.pyi), or None for RGB."},
    {"observe", (PyCFunction)emulator_observe, METH_VARARGS,
     "observe(out, restart=False, frame=None): the preprocessed observation of the last frame (or of frame)."},
    {"forget_action", (PyCFunction)emulator_forget_action, METH_NOARGS, "Apply the next action from its first frame."},
    {"held", (PyCFunction)emulator_held, METH_NOARGS, "The buttons of the last frame run, one mask per port."},
    {"run", (PyCFunction)(void (*)(void))emulator_run, METH_FASTCALL,
     "run(actions, frames[, screen[, after]]): run frames (`after` more of the step follow); convert the last "
     "into screen and say if it fitted."},
    {"reset", (PyCFunction)emulator_reset, METH_NOARGS, "Hard-reset the console."},
    {"screen_shape", (PyCFunction)emulator_screen_shape, METH_NOARGS, "(height, width) of the last frame."},
    {"screen", (PyCFunction)emulator_screen, METH_O, "Write the last frame as RGB into a uint8 array."},
    {"memory", (PyCFunction)rk_py_memory, METH_O, "A writable zero-copy view of a core memory, or None."},
    {"memory_span", (PyCFunction)rk_py_memory_span, METH_VARARGS,
     "memory_span(first, count): one view over descriptors that follow each other in addresses and memory, or None."},
    {"memory_maps", (PyCFunction)rk_py_memory_maps, METH_NOARGS, "The core's memory descriptors, with views."},
    {"capture_audio", (PyCFunction)emulator_capture_audio, METH_O, "Start or stop keeping audio samples."},
    {"take_audio", (PyCFunction)emulator_take_audio, METH_NOARGS, "Return and clear the captured int16 stereo samples."},
    {"serialize", (PyCFunction)rk_py_serialize, METH_NOARGS, "The core's state as bytes."},
    {"unserialize", (PyCFunction)rk_py_unserialize, METH_VARARGS,
     "unserialize(data, exact=True): restore a state; exact: only one of the core's serialize size."},
    {"reload", (PyCFunction)rk_py_reload, METH_NOARGS,
     "Unload the game and load its kept copy again; refused while a view of the core's memory is alive."},
    {"close", (PyCFunction)emulator_close, METH_NOARGS, "Unload the game and the core."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef emulator_getset[] = {
    {"frame", (getter)emulator_get_frame, NULL, "Frames run since the core was loaded.", NULL},
    {"av_asked", (getter)emulator_get_av_asked, NULL, "How often the core asked whether video and audio are wanted.",
     NULL},
    {"av_drawn", (getter)emulator_get_av_drawn, NULL, "How often the core asked and was told to draw the frame.",
     NULL},
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


