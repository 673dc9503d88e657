/*
 * The module functions of retrokit.native._host: decoding RAM fields by a
 * plan, and packing button arrays into RetroPad masks.
 */
#include "host.h"

#include "fields.h"

/* ---- read_fields ------------------------------------------------------------------------------------------------------ */

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

PyObject *rk_py_read_fields(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3 && nargs != 4) return PyErr_Format(PyExc_TypeError, "read_fields() takes (buffers, plan, out[, names])");
    PyObject *names = nargs == 4 && args[3] != Py_None ? args[3] : NULL;
    if (names && !PyTuple_Check(names)) return PyErr_Format(PyExc_TypeError, "names must be a tuple of str");
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
    if (names && PyTuple_GET_SIZE(names) != rows) {
        PyErr_Format(InvalidArgumentError, "read_fields needs one name per plan row (%zd), got %zd", rows,
                     PyTuple_GET_SIZE(names));
        goto done;
    }
    int64_t *dst = out.buf;
    for (Py_ssize_t r = 0; r < rows; r++) dst[r] = rk_decode_field(ptrs, p + r * RK_PLAN_COLUMNS);
    if (names) {
        result = values_by_name(names, p, dst, rows);
    } else {
        result = Py_None;
        Py_INCREF(result);
    }
done:
    for (Py_ssize_t i = 0; i < got; i++) PyBuffer_Release(&bufs[i]);
    if (have_plan) PyBuffer_Release(&plan);
    if (have_out) PyBuffer_Release(&out);
    Py_DECREF(seq);
    return result;
}

/* ---- pack_buttons ----------------------------------------------------------------------------------------------------- */

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

PyObject *rk_py_pack_buttons(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3 && nargs != 4) return PyErr_Format(PyExc_TypeError, "pack_buttons() takes (action, buttons, out[, table])");
    Py_ssize_t buttons = PyLong_AsSsize_t(args[1]);
    if (buttons == -1 && PyErr_Occurred()) return NULL;
    if (buttons < 1 || buttons > 16) return PyErr_Format(InvalidArgumentError, "buttons must be 1 to 16, got %zd", buttons);
    Py_buffer action, out, table = {0};
    if (nargs == 4 && args[3] != Py_None) {
        if (PyObject_GetBuffer(args[3], &table, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) return NULL;
        if (table.itemsize != 2 || table.len != ((Py_ssize_t)2 << buttons)) {
            PyBuffer_Release(&table);
            return PyErr_Format(InvalidArgumentError, "the table must hold 2**%zd uint16 masks, got %zd bytes", buttons,
                                table.len);
        }
    }
    if (PyObject_GetBuffer(args[0], &action, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
        if (table.obj) PyBuffer_Release(&table);
        return NULL;
    }
    if (PyObject_GetBuffer(args[2], &out, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
        PyBuffer_Release(&action);
        if (table.obj) PyBuffer_Release(&table);
        return NULL;
    }
    PyObject *result = NULL;
    const uint16_t *lookup = table.obj ? table.buf : NULL;
    char kind = item_kind(&action);
    Py_ssize_t items = action.len / action.itemsize, players = items / buttons;
    if (!kind) { /* not a number format: the caller converts it itself */
        result = Py_False;
        Py_INCREF(result);
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
        result = Py_True;
        Py_INCREF(result);
    }
    PyBuffer_Release(&action);
    PyBuffer_Release(&out);
    if (table.obj) PyBuffer_Release(&table);
    return result;
}
