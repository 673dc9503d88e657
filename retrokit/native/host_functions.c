/*
 * The module functions of retrokit.native._host: decoding RAM fields by a
 * plan (fields.h), and packing button arrays into RetroPad masks.
 */
#include "host.h"

#include "fields.h"

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

/* An item's button: 0 or 1; -1 for any other value (2, -1, 0.5: not a MultiBinary item). */
static int item_pressed(const char *p, char kind, Py_ssize_t itemsize) {
    if (kind == 'f') {
        float v = *(const float *)p;
        return v == 0.0f ? 0 : v == 1.0f ? 1 : -1;
    }
    if (kind == 'd') {
        double v = *(const double *)p;
        return v == 0.0 ? 0 : v == 1.0 ? 1 : -1;
    }
    /* An integer is 0 or 1 when its low byte is and every other byte is 0, in either byte order. */
    int low = 0, others = 0;
    for (Py_ssize_t k = 0; k < itemsize; k++) {
        unsigned char byte = (unsigned char)p[k];
        if (k == (PY_LITTLE_ENDIAN ? 0 : itemsize - 1)) low = byte;
        else others |= byte;
    }
    return others || low > 1 ? -1 : low;
}

PyObject *rk_py_pack_buttons(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
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
        uint16_t packed[RK_MAX_PORTS];
        const char *p = action.buf;
        int valid = 1;
        for (Py_ssize_t player = 0; player < players && valid; player++) {
            unsigned mask = 0;
            for (Py_ssize_t b = 0; b < buttons; b++, p += action.itemsize) {
                int pressed = item_pressed(p, kind, action.itemsize);
                if (pressed < 0) {
                    valid = 0;
                    break;
                }
                mask |= (unsigned)pressed << b;
            }
            packed[player] = lookup ? lookup[mask] : (uint16_t)mask;
        }
        /* An item other than 0 or 1 writes nothing: the caller's own conversion refuses it, saying which. */
        if (valid) memcpy(out.buf, packed, (size_t)players * sizeof(uint16_t));
        result = Py_NewRef(valid ? Py_True : Py_False);
    }
done:
    PyBuffer_Release(&action);
    PyBuffer_Release(&out);
    PyBuffer_Release(&table);
    return result;
}
