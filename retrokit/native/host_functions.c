/*
 * The module functions of retrokit.native._host: decoding RAM fields by a
 * plan, and converting a frame of any pixel format.
 */
#include "host.h"

#include "fields.h"
#include "isolate.h"
#include "video.h"

/* ---- read_fields ------------------------------------------------------------------------------------------------------ */

#define RK_MAX_BUFFERS 16

PyObject *rk_py_read_fields(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
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

PyObject *rk_py_convert_frame(PyObject *module, PyObject *args) {
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


PyObject *rk_py_rand_sequence(PyObject *module, PyObject *args) {
    unsigned seed;
    Py_ssize_t n;
    if (!PyArg_ParseTuple(args, "In", &seed, &n)) return NULL;
    if (n < 0) return PyErr_Format(InvalidArgumentError, "n must be 0 or more, got %zd", n);
    rk_rand r;
    rk_rand_seed(&r, seed);
    PyObject *out = PyList_New(n);
    for (Py_ssize_t i = 0; out && i < n; i++) PyList_SET_ITEM(out, i, PyLong_FromLong(rk_rand_next(&r)));
    return out;
}
