/*
 * What an Emulator hands out: its screen as RGB, zero-copy views of its
 * memory (Memory objects keep their emulator alive), audio, and states.
 */
#include "host.h"

#include "video.h"

typedef struct {
    PyObject_HEAD
    EmulatorObject *owner;
    void *ptr;
    Py_ssize_t size;
} MemoryObject;

static int memory_getbuffer(MemoryObject *self, Py_buffer *view, int flags) {
    if (self->owner->closed && !self->owner->core.handle)
        return rk_py_fail(CoreError, "the emulator behind this memory is closed");
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

PyTypeObject MemoryType = {
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

PyObject *emulator_screen_shape(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_core *c = &self->core; /* before the first frame, the size the core announced */
    unsigned w = c->frame_data ? c->frame_width : c->av.geometry.base_width;
    unsigned h = c->frame_data ? c->frame_height : c->av.geometry.base_height;
    rk_py_leave(self);
    return Py_BuildValue("(II)", h, w);
}

PyObject *emulator_screen(EmulatorObject *self, PyObject *out) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_core *c = &self->core;
    unsigned w = c->frame_data ? c->frame_width : c->av.geometry.base_width;
    unsigned h = c->frame_data ? c->frame_height : c->av.geometry.base_height;
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

PyObject *emulator_memory(EmulatorObject *self, PyObject *arg) {
    long kind = PyLong_AsLong(arg);
    if (kind == -1 && PyErr_Occurred()) return NULL;
    if (kind < 0 || kind > 255) return PyErr_Format(InvalidArgumentError, "memory kind must be 0..255, got %ld", kind);
    if (rk_py_enter(self, 1)) return NULL;
    rk_enter(&self->core);
    void *ptr = self->core.api.get_memory_data((unsigned)kind);
    size_t size = self->core.api.get_memory_size((unsigned)kind);
    rk_leave();
    rk_py_leave(self);
    if (!ptr || !size) Py_RETURN_NONE;
    return memory_view(self, ptr, size);
}

PyObject *emulator_memory_maps(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_py_leave(self);
    PyObject *list = PyList_New(0);
    for (int i = 0; list && i < self->core.n_maps; i++) {
        rk_memmap *m = &self->core.maps[i];
        /* If making the view fails, Py_BuildValue's N passes the error on. */
        PyObject *view = m->ptr && m->len ? memory_view(self, (uint8_t *)m->ptr + m->offset, m->len)
                                          : Py_NewRef(Py_None);
        PyObject *d = Py_BuildValue("{s:K,s:n,s:n,s:n,s:n,s:s,s:N}", "flags", (unsigned long long)m->flags, "start",
                                    (Py_ssize_t)m->start, "select", (Py_ssize_t)m->select, "disconnect",
                                    (Py_ssize_t)m->disconnect, "length", (Py_ssize_t)m->len, "addrspace",
                                    m->addrspace, "memory", view);
        if (!d || PyList_Append(list, d) < 0) Py_CLEAR(list);
        Py_XDECREF(d);
    }
    return list;
}

PyObject *emulator_capture_audio(EmulatorObject *self, PyObject *arg) {
    int on = PyObject_IsTrue(arg);
    if (on < 0) return NULL;
    self->core.capture_audio = on;
    if (!on) self->core.audio_len = 0;
    Py_RETURN_NONE;
}

PyObject *emulator_take_audio(EmulatorObject *self, PyObject *unused) {
    PyObject *out = PyBytes_FromStringAndSize((const char *)self->core.audio, (Py_ssize_t)(self->core.audio_len * 2));
    self->core.audio_len = 0;
    return out;
}

PyObject *emulator_serialize(EmulatorObject *self, PyObject *unused) {
    if (rk_py_enter(self, 1)) return NULL;
    rk_enter(&self->core);
    size_t size = self->core.api.serialize_size();
    rk_leave();
    PyObject *out = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)size);
    char *dst = out ? PyBytes_AS_STRING(out) : NULL;
    bool ok = false;
    if (out) {
        Py_BEGIN_ALLOW_THREADS
        rk_enter(&self->core);
        ok = self->core.api.serialize(dst, size);
        rk_leave();
        Py_END_ALLOW_THREADS
    }
    rk_py_leave(self);
    if (out && !ok) Py_SETREF(out, PyErr_Format(CoreError, "the core refused to serialize its state"));
    return out;
}

PyObject *emulator_unserialize(EmulatorObject *self, PyObject *arg) {
    Py_buffer buf;
    if (PyObject_GetBuffer(arg, &buf, PyBUF_SIMPLE) < 0) return NULL;
    if (rk_py_enter(self, 1)) return rk_py_release(&buf, NULL);
    rk_enter(&self->core);
    size_t size = self->core.api.serialize_size();
    rk_leave();
    bool fits = (size_t)buf.len == size, ok = false;
    if (fits) {
        Py_BEGIN_ALLOW_THREADS
        rk_enter(&self->core);
        ok = self->core.api.unserialize(buf.buf, size);
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
                     "make it again with this core", size);
    return rk_py_release(&buf, ok ? Py_NewRef(Py_None) : NULL);
}
