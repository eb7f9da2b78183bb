"""A numpy executor of a TFLite graph, straight from the flatbuffer (tests only).

Independent of the ONNX conversion: it runs the TFLite operators in TFLite's own NHWC
layout, in float64, including the DEQUANTIZE and DENSIFY operators themselves, with its
own padding arithmetic. It shares only the schema-less flatbuffer reader
(tflite_model.py) with the converter. Used by agreement_test.py to check what cv::dnn
computes on the converted ONNX model.
"""

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from tflite_model import TfliteModel, densify


def _pads(size, kernel, stride, dilation, padding):
    """TFLite padding along one axis: VALID none; SAME the odd pixel at the end."""
    if padding == 1:  # VALID
        return 0, 0
    out = -(-size // stride)
    need = (out - 1) * stride + (kernel - 1) * dilation + 1 - size
    need = max(need, 0)
    return need // 2, need - need // 2


def _activate(x, act):
    if act == 0:
        return x
    if act == 1:
        return np.maximum(x, 0)
    if act == 3:
        return np.clip(x, 0, 6)
    raise NotImplementedError("fused activation %d" % act)


def _windows(x, kh, kw, sh, sw, dh, dw, padding, fill):
    """(N, OH, OW, C, kh, kw) windows of x (NHWC), padded TFLite's way."""
    top, bottom = _pads(x.shape[1], kh, sh, dh, padding)
    left, right = _pads(x.shape[2], kw, sw, dw, padding)
    x = np.pad(x, ((0, 0), (top, bottom), (left, right), (0, 0)), constant_values=fill)
    win = sliding_window_view(x, ((kh - 1) * dh + 1, (kw - 1) * dw + 1), axis=(1, 2))
    return win[:, ::sh, ::sw, :, ::dh, ::dw]


class Reference:
    def __init__(self, path):
        self.model = TfliteModel(path)

    def run(self, image):
        """Runs the graph on `image` (NHWC, float); returns {output name: float32 array}."""
        m = self.model
        values = {}
        for t in m.tensors:
            if t.data is not None and t.sparsity is None:
                values[t.index] = t.data
        (inp,) = m.inputs
        values[inp] = np.asarray(image, np.float64).reshape(m.tensors[inp].shape)
        for op in m.operators:
            ins = [values.get(i) if i >= 0 else None for i in op.inputs]
            values[op.outputs[0]] = self._op(op, ins, values)
        return {m.tensors[o].name: values[o].astype(np.float32) for o in m.outputs}

    def _op(self, op, ins, values):
        m = self.model
        out_shape = m.tensors[op.outputs[0]].shape
        name = op.name
        if name == "DEQUANTIZE":
            return ins[0].astype(np.float64)
        if name == "DENSIFY":
            return densify(m.tensors[op.inputs[0]])
        if name in ("CONV_2D", "DEPTHWISE_CONV_2D"):
            x, w = ins[0], ins[1].astype(np.float64)
            b = ins[2] if len(ins) > 2 else None
            if name == "CONV_2D":
                pad, sw, sh, act = op.option(0, "b"), op.option(1, "i"), op.option(2, "i"), op.option(3, "b")
                dw, dh = op.option(4, "i", 1), op.option(5, "i", 1)
                win = _windows(x, w.shape[1], w.shape[2], sh, sw, dh, dw, pad, 0.0)
                # win: N OH OW C kh kw; w: O kh kw C
                y = np.einsum("nhwcij,oijc->nhwo", win, w, optimize=True)
            else:
                pad, sw, sh = op.option(0, "b"), op.option(1, "i"), op.option(2, "i")
                mult, act = op.option(3, "i"), op.option(4, "b")
                dw, dh = op.option(5, "i", 1), op.option(6, "i", 1)
                win = _windows(x, w.shape[1], w.shape[2], sh, sw, dh, dw, pad, 0.0)
                c = x.shape[3]
                wk = w[0].reshape(w.shape[1], w.shape[2], c, mult)  # kh kw C M
                y = np.einsum("nhwcij,ijcm->nhwcm", win, wk, optimize=True)
                y = y.reshape(y.shape[0], y.shape[1], y.shape[2], c * mult)
            if b is not None:
                y = y + b.astype(np.float64)
            return _activate(y, act)
        if name == "ADD":
            return _activate(ins[0].astype(np.float64) + ins[1], op.option(0, "b"))
        if name == "PRELU":
            return np.where(ins[0] >= 0, ins[0], ins[0] * ins[1])
        if name == "PAD":
            return np.pad(ins[0], [tuple(int(v) for v in p) for p in ins[1]])
        if name == "MAX_POOL_2D":
            pad, sw, sh = op.option(0, "b"), op.option(1, "i"), op.option(2, "i")
            fw, fh = op.option(3, "i"), op.option(4, "i")
            win = _windows(ins[0], fh, fw, sh, sw, 1, 1, pad, -np.inf)
            return _activate(win.max(axis=(4, 5)), op.option(5, "b"))
        if name == "RESHAPE":
            return ins[0].reshape(out_shape)
        if name == "RESIZE_BILINEAR":
            x = ins[0]
            oh, ow = int(ins[1][0]), int(ins[1][1])
            align, half = op.option(2, "b"), op.option(3, "b")
            if align:
                raise NotImplementedError("align_corners")

            def axis_weights(n_in, n_out):
                scale = n_in / n_out
                o = np.arange(n_out, dtype=np.float64)
                src = (o + 0.5) * scale - 0.5 if half else o * scale
                src = np.clip(src, 0, n_in - 1)
                lo = np.floor(src).astype(int)
                hi = np.minimum(lo + 1, n_in - 1)
                return lo, hi, src - lo

            ylo, yhi, wy = axis_weights(x.shape[1], oh)
            xlo, xhi, wx = axis_weights(x.shape[2], ow)
            wy = wy[None, :, None, None]
            wx = wx[None, None, :, None]
            top = x[:, ylo][:, :, xlo] * (1 - wx) + x[:, ylo][:, :, xhi] * wx
            bottom = x[:, yhi][:, :, xlo] * (1 - wx) + x[:, yhi][:, :, xhi] * wx
            return top * (1 - wy) + bottom * wy
        if name == "DEPTH_TO_SPACE":
            bs = op.option(0, "i")
            n, h, w, c = ins[0].shape
            y = ins[0].reshape(n, h, w, bs, bs, c // (bs * bs)).transpose(0, 1, 3, 2, 4, 5)
            return y.reshape(n, h * bs, w * bs, c // (bs * bs))
        if name == "CONCATENATION":
            return _activate(np.concatenate(ins, axis=op.option(0, "i")), op.option(1, "b"))
        if name == "MEAN":
            axes = tuple(int(a) for a in np.asarray(ins[1]).reshape(-1))
            return ins[0].mean(axis=axes, keepdims=bool(op.option(0, "b")))
        if name == "FULLY_CONNECTED":
            w = ins[1].astype(np.float64)
            y = ins[0].reshape(-1, w.shape[1]) @ w.T
            if len(ins) > 2 and ins[2] is not None:
                y = y + ins[2]
            return _activate(y.reshape(out_shape), op.option(0, "b"))
        if name == "LOGISTIC":
            return 1.0 / (1.0 + np.exp(-ins[0]))
        if name == "STRIDED_SLICE":
            begin, end, strides = ins[1], ins[2], ins[3]
            return ins[0][tuple(slice(int(b), int(e), int(s)) for b, e, s in zip(begin, end, strides))]
        raise NotImplementedError("TFLite op %s" % name)
