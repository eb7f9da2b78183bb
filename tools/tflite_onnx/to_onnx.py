"""Converts a MediaPipe TFLite graph to an ONNX graph that arco runs (XNNPACK or cv::dnn).

Our own converter, written from the op semantics of TensorFlow Lite and ONNX
(docs/detect.md). Choices:
- DEQUANTIZE (fp16 -> fp32) and DENSIFY (sparse -> dense) of constants are folded, so
  the ONNX graph holds float32 initializers only.
- 4-D activations are NCHW (the input is NCHW: [1, 3, H, W]); weights are transposed
  from TFLite's OHWI (conv) / 1HWO (depthwise). A RESHAPE of a 4-D tensor and a 4-D
  graph output first transpose back to NHWC, so every output has its TFLite shape and
  element order.
- TFLite SAME padding puts the odd pixel at the end: pads are explicit per side.
- OpenCV 4.6's ONNX dialect: Clip with min/max attributes (opset-6 style, although the
  model says opset 11, which cv::dnn needs for Resize's half_pixel mode), Slice listing
  only the sliced axes.
- The graph is what the TFLite graph computes, layer for layer: arco runs it with
  XNNPACK (src/arco/detect/xnnpack_graph.h), which has kernels for every layer, or with
  cv::dnn. (A rewrite of the 5 x 5 depthwise layers for cv::dnn's 3 x 3 fast path, 6d4a031,
  was dropped with XNNPACK: docs/detect.md.)
- Only the outputs arco reads are kept (`keep_outputs`), with the nodes and constants they
  need: cv::dnn runs every layer up to the last requested output in node order, so a head
  nobody reads (pose_landmark's segmentation mask and heatmaps) would cost its time on
  every frame even when not requested.
Deterministic: the same TFLite file gives the same ONNX bytes.
"""

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

from tflite_model import TfliteModel, densify

OPSET = 11
# fused_activation_function values (schema.fbs ActivationFunctionType).
ACT_NONE, ACT_RELU, ACT_RELU6 = 0, 1, 3
PAD_SAME, PAD_VALID = 0, 1
NHWC_TO_NCHW_AXIS = {0: 0, 1: 2, 2: 3, 3: 1}


def same_pads(in_size, kernel, stride, dilation=1):
    """(before, after) of TFLite SAME padding: the odd pixel goes after."""
    out = (in_size + stride - 1) // stride
    effective = (kernel - 1) * dilation + 1
    total = max((out - 1) * stride + effective - in_size, 0)
    return total // 2, total - total // 2


def constant_value(model, producers, index):
    """The float value of a constant tensor, folding DEQUANTIZE and DENSIFY; else None."""
    tensor = model.tensors[index]
    op = producers.get(index)
    if op is not None:
        if op.name == "DEQUANTIZE":
            src = constant_value(model, producers, op.inputs[0])
            return None if src is None else src.astype(np.float32)
        if op.name == "DENSIFY":
            return densify(model.tensors[op.inputs[0]])
        return None
    if tensor.data is None:
        return None
    if tensor.sparsity is not None:
        return densify(tensor)
    return tensor.data


class Converter:
    def __init__(self, model):
        self.model = model
        self.producers = {}
        for op in model.operators:
            for o in op.outputs:
                self.producers[o] = op
        self.nodes = []
        self.initializers = []
        self.names = {}  # tflite tensor index -> ONNX value name
        self.counter = 0

    def fresh(self, base):
        self.counter += 1
        return "%s__%d" % (base, self.counter)

    def const(self, base, array):
        name = self.fresh(base)
        self.initializers.append(numpy_helper.from_array(np.ascontiguousarray(array), name))
        return name

    def node(self, op_type, inputs, outputs, **attrs):
        self.nodes.append(helper.make_node(op_type, inputs, outputs,
                                           name=self.fresh(op_type), **attrs))

    def pad(self, x, onnx_pads, out):
        """A constant-zero Pad of `x` by `onnx_pads` (ONNX order: all begins, then all ends)."""
        self.node("Pad", [x, self.const("pads", np.array(onnx_pads, np.int64)),
                          self.const("value", np.array(0, np.float32))], [out], mode="constant")

    def slice(self, x, starts, ends, axes, steps, out):
        """A Slice of `x` (OpenCV 4.6: only the sliced axes listed)."""
        self.node("Slice", [x, self.const("starts", np.array(starts, np.int64)),
                            self.const("ends", np.array(ends, np.int64)),
                            self.const("axes", np.array(axes, np.int64)),
                            self.const("steps", np.array(steps, np.int64))], [out])

    def cval(self, index):
        return constant_value(self.model, self.producers, index)

    def shape(self, index):
        return self.model.tensors[index].shape

    def out_name(self, index):
        name = self.model.tensors[index].name
        if index in self.model.outputs:
            if len(self.shape(index)) == 4:
                return self.fresh(name + "_nchw")  # transposed to NHWC at the end
            return name
        return self.fresh(name)

    def activation(self, op, act, index, raw):
        """Applies a fused activation to `raw`, naming the result for tensor `index`."""
        if act == ACT_NONE:
            out = raw
        elif act == ACT_RELU:
            out = self.fresh("relu")
            self.node("Relu", [raw], [out])
        elif act == ACT_RELU6:
            out = self.fresh("relu6")
            self.node("Clip", [raw], [out], min=0.0, max=6.0)
        else:
            raise NotImplementedError("%s: fused activation %d" % (op.name, act))
        self.names[index] = out

    def conv(self, op, depthwise):
        x, w_idx = op.inputs[0], op.inputs[1]
        w = self.cval(w_idx)
        in_shape = self.shape(x)
        if depthwise:
            # TFLite 1HWO (O = C * multiplier) -> ONNX O1HW, group = C.
            stride_w, stride_h = op.option(1, "i"), op.option(2, "i")
            act = op.option(4, "b")
            dil_w, dil_h = op.option(5, "i", 1), op.option(6, "i", 1)
            weight = np.transpose(w, (3, 0, 1, 2))
            group = in_shape[3]
        else:
            stride_w, stride_h = op.option(1, "i"), op.option(2, "i")
            act = op.option(3, "b")
            dil_w, dil_h = op.option(4, "i", 1), op.option(5, "i", 1)
            weight = np.transpose(w, (0, 3, 1, 2))  # OHWI -> OIHW
            group = 1
        kh, kw = weight.shape[2], weight.shape[3]
        if op.option(0, "b") == PAD_SAME:
            top, bottom = same_pads(in_shape[1], kh, stride_h, dil_h)
            left, right = same_pads(in_shape[2], kw, stride_w, dil_w)
        else:
            top = bottom = left = right = 0
        bias = None
        if len(op.inputs) > 2 and op.inputs[2] >= 0:
            bias = self.cval(op.inputs[2]).astype(np.float32)
        inputs = [self.names[x], self.const("W", weight.astype(np.float32))]
        if bias is not None:
            inputs.append(self.const("B", bias))
        raw = self.fresh("conv")
        self.node("Conv", inputs, [raw], kernel_shape=[kh, kw], strides=[stride_h, stride_w],
                  dilations=[dil_h, dil_w], pads=[top, left, bottom, right], group=group)
        self.activation(op, act, op.outputs[0], raw)

    def to_nhwc(self, index):
        """The ONNX name of tensor `index` in TFLite's layout (transposed if 4-D)."""
        name = self.names[index]
        if len(self.shape(index)) != 4:
            return name
        out = self.fresh("nhwc")
        self.node("Transpose", [name], [out], perm=[0, 2, 3, 1])
        return out

    def convert_op(self, op):
        m = self.model
        o = op.outputs[0]
        if op.name in ("DEQUANTIZE", "DENSIFY"):
            if self.cval(o) is None:
                raise NotImplementedError("%s of a non-constant tensor" % op.name)
            return  # folded into the consumer's constants
        if op.name == "CONV_2D":
            return self.conv(op, depthwise=False)
        if op.name == "DEPTHWISE_CONV_2D":
            return self.conv(op, depthwise=True)
        if op.name == "ADD":
            inputs = []
            for i in op.inputs:
                c = self.cval(i)
                if c is None:
                    inputs.append(self.names[i])
                elif c.ndim == 4:
                    inputs.append(self.const("addc", np.transpose(c, (0, 3, 1, 2))))
                else:
                    raise NotImplementedError("ADD with a constant of rank %d" % c.ndim)
            raw = self.fresh("add")
            self.node("Add", inputs, [raw])
            return self.activation(op, op.option(0, "b"), o, raw)
        if op.name == "PRELU":
            alpha = self.cval(op.inputs[1])
            if len(self.shape(op.inputs[0])) != 4 or alpha.size != alpha.shape[-1]:
                raise NotImplementedError("PRELU other than per channel")
            slope = self.const("slope", alpha.reshape(-1, 1, 1).astype(np.float32))
            out = self.out_name(o)
            self.node("PRelu", [self.names[op.inputs[0]], slope], [out])
            self.names[o] = out
            return
        if op.name == "PAD":
            pads = self.cval(op.inputs[1]).astype(np.int64)
            onnx_pads = [0] * 8
            for axis in range(4):
                a = NHWC_TO_NCHW_AXIS[axis]
                onnx_pads[a], onnx_pads[4 + a] = int(pads[axis][0]), int(pads[axis][1])
            out = self.out_name(o)
            self.pad(self.names[op.inputs[0]], onnx_pads, out)
            self.names[o] = out
            return
        if op.name == "MAX_POOL_2D":
            in_shape = self.shape(op.inputs[0])
            stride_w, stride_h = op.option(1, "i"), op.option(2, "i")
            fw, fh = op.option(3, "i"), op.option(4, "i")
            if op.option(0, "b") == PAD_SAME:
                top, bottom = same_pads(in_shape[1], fh, stride_h)
                left, right = same_pads(in_shape[2], fw, stride_w)
            else:
                top = bottom = left = right = 0
            raw = self.fresh("pool")
            self.node("MaxPool", [self.names[op.inputs[0]]], [raw], kernel_shape=[fh, fw],
                      strides=[stride_h, stride_w], pads=[top, left, bottom, right])
            return self.activation(op, op.option(5, "b"), o, raw)
        if op.name == "RESHAPE":
            new_shape = np.array(self.shape(o), np.int64)
            out = self.out_name(o)
            self.node("Reshape", [self.to_nhwc(op.inputs[0]), self.const("shape", new_shape)], [out])
            self.names[o] = out
            return
        if op.name == "RESIZE_BILINEAR":
            if op.option(2, "b"):
                raise NotImplementedError("RESIZE_BILINEAR with align_corners")
            mode = "half_pixel" if op.option(3, "b") else "asymmetric"
            size = self.cval(op.inputs[1]).astype(np.int64)
            in_shape = self.shape(op.inputs[0])
            sizes = np.array([in_shape[0], in_shape[3], size[0], size[1]], np.int64)
            out = self.out_name(o)
            self.node("Resize", [self.names[op.inputs[0]], self.const("roi", np.zeros(0, np.float32)),
                                 self.const("scales", np.zeros(0, np.float32)),
                                 self.const("sizes", sizes)], [out],
                      mode="linear", coordinate_transformation_mode=mode)
            self.names[o] = out
            return
        if op.name == "DEPTH_TO_SPACE":
            # TFLite's NHWC depth_to_space is ONNX's DCR mode.
            out = self.out_name(o)
            self.node("DepthToSpace", [self.names[op.inputs[0]]], [out],
                      blocksize=op.option(0, "i"), mode="DCR")
            self.names[o] = out
            return
        if op.name == "CONCATENATION":
            axis = op.option(0, "i")
            rank = len(self.shape(o))
            if axis < 0:
                axis += rank
            if rank == 4:
                axis = NHWC_TO_NCHW_AXIS[axis]
            raw = self.fresh("concat")
            self.node("Concat", [self.names[i] for i in op.inputs], [raw], axis=axis)
            return self.activation(op, op.option(1, "b"), o, raw)
        if op.name == "MEAN":
            axes = sorted(int(a) for a in self.cval(op.inputs[1]).reshape(-1))
            if len(self.shape(op.inputs[0])) != 4 or axes != [1, 2]:
                raise NotImplementedError("MEAN other than over height and width")
            pooled = self.fresh("gap")
            self.node("GlobalAveragePool", [self.names[op.inputs[0]]], [pooled])
            out = self.out_name(o)
            if op.option(0, "b"):
                self.node("Identity", [pooled], [out])
            else:
                self.node("Flatten", [pooled], [out], axis=1)
            self.names[o] = out
            return
        if op.name == "FULLY_CONNECTED":
            if op.option(2, "b"):
                raise NotImplementedError("FULLY_CONNECTED with keep_num_dims")
            w = self.cval(op.inputs[1]).astype(np.float32)
            x = self.names[op.inputs[0]]
            if len(self.shape(op.inputs[0])) != 2:
                flat = self.fresh("flat")
                self.node("Reshape", [self.to_nhwc(op.inputs[0]),
                                      self.const("shape", np.array([-1, w.shape[1]], np.int64))], [flat])
                x = flat
            inputs = [x, self.const("W", w)]
            if len(op.inputs) > 2 and op.inputs[2] >= 0:
                inputs.append(self.const("B", self.cval(op.inputs[2]).astype(np.float32)))
            raw = self.fresh("fc")
            self.node("Gemm", inputs, [raw], transB=1)
            return self.activation(op, op.option(0, "b"), o, raw)
        if op.name == "LOGISTIC":
            out = self.out_name(o)
            self.node("Sigmoid", [self.names[op.inputs[0]]], [out])
            self.names[o] = out
            return
        if op.name == "STRIDED_SLICE":
            begin = self.cval(op.inputs[1]).astype(np.int64)
            end = self.cval(op.inputs[2]).astype(np.int64)
            strides = self.cval(op.inputs[3]).astype(np.int64)
            if any(op.option(k, "i") for k in range(6)):
                raise NotImplementedError("STRIDED_SLICE with masks")
            in_shape = self.shape(op.inputs[0])
            rank = len(in_shape)
            starts, ends, axes, steps = [], [], [], []
            # OpenCV 4.6 wants only the axes that are actually sliced.
            for axis in range(rank):
                if begin[axis] == 0 and end[axis] >= in_shape[axis] and strides[axis] == 1:
                    continue
                starts.append(begin[axis])
                ends.append(end[axis])
                axes.append(NHWC_TO_NCHW_AXIS[axis] if rank == 4 else axis)
                steps.append(strides[axis])
            out = self.out_name(o)
            self.slice(self.names[op.inputs[0]], starts, ends, axes, steps, out)
            self.names[o] = out
            return
        raise NotImplementedError("TFLite op %s" % op.name)

    def prune(self, output_names):
        """Drops the nodes and constants that no output in `output_names` depends on."""
        needed = set(output_names)
        kept = []
        for node in reversed(self.nodes):
            if any(o in needed for o in node.output):
                kept.append(node)
                needed.update(node.input)
        kept.reverse()
        self.nodes = kept
        self.initializers = [i for i in self.initializers if i.name in needed]

    def convert(self, graph_name, keep_outputs=None):
        """The ONNX model; `keep_outputs` lists the TFLite output tensors to keep (all: None)."""
        m = self.model
        (in_idx,) = m.inputs
        n, h, w, c = self.shape(in_idx)
        in_name = m.tensors[in_idx].name
        self.names[in_idx] = in_name
        for op in m.operators:
            self.convert_op(op)
        kept = list(m.outputs)
        if keep_outputs is not None:
            names = [m.tensors[o].name for o in m.outputs]
            missing = [k for k in keep_outputs if k not in names]
            if missing:
                raise ValueError("%s: no output %s (it has %s)" % (graph_name, missing, names))
            kept = [o for o in m.outputs if m.tensors[o].name in keep_outputs]
        outputs = []
        for o in kept:
            name = m.tensors[o].name
            shape = self.shape(o)
            if len(shape) == 4:
                self.node("Transpose", [self.names[o]], [name], perm=[0, 2, 3, 1])
            elif self.names[o] != name:
                self.node("Identity", [self.names[o]], [name])
            outputs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, shape))
        self.prune([o.name for o in outputs])
        graph = helper.make_graph(
            self.nodes, graph_name,
            [helper.make_tensor_value_info(in_name, TensorProto.FLOAT, [n, c, h, w])],
            outputs, initializer=self.initializers)
        model = helper.make_model(graph, producer_name="arco tflite_onnx",
                                  opset_imports=[helper.make_opsetid("", OPSET)])
        model.ir_version = 7
        return model


def convert_file(tflite_path, onnx_path, graph_name, keep_outputs=None):
    model = Converter(TfliteModel(tflite_path)).convert(graph_name, keep_outputs)
    with open(onnx_path, "wb") as f:
        f.write(model.SerializeToString())


if __name__ == "__main__":
    import sys
    convert_file(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else "model")
