/*
 * What the Emulator type of retrokit.native._host hands out of its core's
 * memory: zero-copy views (Memory objects, which keep their emulator alive
 * and count the buffers exported, so a reload can refuse while one lives) of
 * a core memory, of each descriptor of its memory map, and of descriptors that
 * follow each other.
 */
#include "host.h"

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

PyObject *rk_py_memory(EmulatorObject *self, PyObject *arg) {
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

PyObject *rk_py_memory_maps(EmulatorObject *self, PyObject *unused) {
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

/* One view over the memory of descriptors first..first+count-1, when each one's console addresses and memory
 * begin where the one before ends (FCEUmm maps its 2 KiB of RAM as two 1 KiB descriptors over one array): a
 * field across them is read as stable-retro reads it, from the bytes that follow. None where they do not follow. */
PyObject *rk_py_memory_span(EmulatorObject *self, PyObject *args) {
    int first, count;
    if (!PyArg_ParseTuple(args, "ii", &first, &count)) return NULL;
    if (rk_py_enter(self, 1)) return NULL;
    rk_py_leave(self);
    rk_core *c = &self->core;
    if (first < 0 || count < 1 || first >= c->n_maps || count > c->n_maps - first)
        return PyErr_Format(InvalidArgumentError, "expected descriptors within the core's %d, got %d from %d", c->n_maps,
                            count, first);
    const rk_memmap *m = &c->maps[first];
    if (!m->ptr || !m->len) Py_RETURN_NONE;
    uint8_t *base = (uint8_t *)m->ptr + m->offset;
    size_t total = m->len;
    for (int i = first + 1; i < first + count; i++) {
        const rk_memmap *n = &c->maps[i];
        if (!n->ptr || !n->len || (uint8_t *)n->ptr + n->offset != base + total || n->start != m->start + total ||
            (n->flags ^ m->flags))
            Py_RETURN_NONE;
        total += n->len;
    }
    return memory_view(self, base, total);
}
