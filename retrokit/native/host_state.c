/*
 * The state calls of retrokit.native._host's Emulator: serializing, restoring, and reloading the game (for a
 * core that keeps part of the console outside its states, so that only a fresh load plays a state alike).
 *
 * A reload frees the memory the core showed, so it is refused while any view of that memory is alive: no
 * buffer can point at freed memory, and the caller makes its views again afterwards.
 */
#include "host.h"

PyObject *rk_py_serialize(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_enter(&self->core);
    size_t size = self->core.api.serialize_size();
    rk_leave();
    PyObject *out = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)size);
    char *dst = out ? PyBytes_AS_STRING(out) : NULL;
    bool ok = false;
    if (out) {
        Py_BEGIN_ALLOW_THREADS
        /* A core may write less than its size (Genesis Plus GX: a quarter): the rest is zeros, not whatever
         * the allocator left there, so that a state's bytes depend on the game alone. */
        memset(dst, 0, size);
        rk_enter(&self->core);
        ok = self->core.api.serialize(dst, size);
        rk_leave();
        Py_END_ALLOW_THREADS
    }
    rk_py_leave(self);
    if (out && !ok) Py_SETREF(out, PyErr_Format(CoreError, "the core refused to serialize its state"));
    return out;
}

/* exact: the core reads retro_serialize_size bytes whatever length it is given, so only a state of that length
   may reach it. Otherwise (a core that parses the state within the length it is given, as stella does) the state
   goes as it is, and the core refuses what it cannot read. */
PyObject *rk_py_unserialize(EmulatorObject *self, PyObject *args) {
    Py_buffer buf;
    int exact = 1;
    if (!PyArg_ParseTuple(args, "y*|p", &buf, &exact)) return NULL;
    if (rk_py_enter(self, 1)) return rk_py_release(&buf, NULL);
    rk_enter(&self->core);
    size_t size = self->core.api.serialize_size();
    rk_leave();
    bool fits = exact ? (size_t)buf.len == size : buf.len > 0, ok = false;
    if (fits) {
        Py_BEGIN_ALLOW_THREADS
        rk_enter(&self->core);
        ok = self->core.api.unserialize(buf.buf, (size_t)buf.len);
        rk_leave();
        Py_END_ALLOW_THREADS
        self->core.have_held = 0;
    }
    rk_py_leave(self); /* before raising: it may call the log callback */
    if (!fits)
        PyErr_Format(StateError, "expected a state of %zu bytes for this core, got %zd bytes: the state is truncated, "
                     "corrupt, or was made by another core or core version; make it again with this core",
                     size, buf.len);
    else if (!ok)
        PyErr_Format(StateError, "the core refused the state (%zu bytes): it is corrupt or was made by another core; "
                     "make it again with this core", (size_t)buf.len);
    return rk_py_release(&buf, ok ? Py_NewRef(Py_None) : NULL);
}

PyObject *rk_py_reload(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    /* Every memoryview of the core's memory, and every array made from one, holds an export until it dies. */
    Py_ssize_t alive = self->core.game_path ? self->exports : 0;
    int rc = 0;
    if (!alive) {
        Py_BEGIN_ALLOW_THREADS
        rc = rk_core_reload_game(&self->core);
        Py_END_ALLOW_THREADS
    }
    rk_py_leave(self); /* before raising: it may call the log callback */
    if (alive)
        return PyErr_Format(CoreError, "expected no view of this emulator's memory to be alive before reloading its "
                            "game (the reload frees that memory); found %zd: release them (memoryview.release(), "
                            "or drop the arrays made from them) and make them again after the reload", alive);
    if (rc) return PyErr_Format(CoreError, "cannot reload the game: %s", self->core.error);
    Py_RETURN_NONE;
}
