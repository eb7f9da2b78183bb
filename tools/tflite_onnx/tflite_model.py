"""Reads a TFLite model (a flatbuffer) without its schema, by field index.

Only what MediaPipe's pose and hand models use is read (docs/detect.md). Field indices
follow TensorFlow Lite's schema.fbs: Model (operator_codes 1, subgraphs 2, buffers 4),
SubGraph (tensors 0, inputs 1, outputs 2, operators 3), Tensor (shape 0, type 1,
buffer 2, name 3, sparsity 6), Operator (opcode_index 0, inputs 1, outputs 2,
builtin_options 4), OperatorCode (deprecated_builtin_code 0, builtin_code 3).
"""

import struct

import numpy as np

# Builtin operator codes (schema.fbs BuiltinOperator) of the ops these models use.
OP_NAMES = {
    0: "ADD", 2: "CONCATENATION", 3: "CONV_2D", 4: "DEPTHWISE_CONV_2D",
    5: "DEPTH_TO_SPACE", 6: "DEQUANTIZE", 9: "FULLY_CONNECTED", 14: "LOGISTIC",
    17: "MAX_POOL_2D", 18: "MUL", 19: "RELU", 21: "RELU6", 22: "RESHAPE",
    23: "RESIZE_BILINEAR", 34: "PAD", 40: "MEAN", 45: "STRIDED_SLICE", 54: "PRELU",
    124: "DENSIFY",
}

# TensorType -> numpy dtype.
TENSOR_TYPES = {0: np.float32, 1: np.float16, 2: np.int32, 3: np.uint8, 4: np.int64,
                9: np.int8, 7: np.int16}


class Table:
    """A flatbuffer table at byte position `pos` of `buf`."""

    def __init__(self, buf, pos):
        self.buf = buf
        self.pos = pos
        vtable = pos - struct.unpack_from("<i", buf, pos)[0]
        vt_size = struct.unpack_from("<H", buf, vtable)[0]
        self.offsets = [struct.unpack_from("<H", buf, vtable + 4 + 2 * i)[0]
                        for i in range((vt_size - 4) // 2)]

    def _field(self, index):
        if index < len(self.offsets) and self.offsets[index] != 0:
            return self.pos + self.offsets[index]
        return None

    def scalar(self, index, fmt, default=0):
        at = self._field(index)
        return default if at is None else struct.unpack_from("<" + fmt, self.buf, at)[0]

    def _target(self, index):
        at = self._field(index)
        if at is None:
            return None
        return at + struct.unpack_from("<I", self.buf, at)[0]

    def table(self, index):
        at = self._target(index)
        return None if at is None else Table(self.buf, at)

    def string(self, index):
        at = self._target(index)
        if at is None:
            return ""
        n = struct.unpack_from("<I", self.buf, at)[0]
        return bytes(self.buf[at + 4:at + 4 + n]).decode("utf-8")

    def vector(self, index, fmt):
        """A vector of scalars as a numpy array (fmt: a numpy dtype string)."""
        at = self._target(index)
        if at is None:
            return None
        n = struct.unpack_from("<I", self.buf, at)[0]
        return np.frombuffer(self.buf, dtype=np.dtype(fmt), count=n, offset=at + 4)

    def tables(self, index):
        at = self._target(index)
        if at is None:
            return []
        n = struct.unpack_from("<I", self.buf, at)[0]
        out = []
        for i in range(n):
            elem = at + 4 + 4 * i
            out.append(Table(self.buf, elem + struct.unpack_from("<I", self.buf, elem)[0]))
        return out


class Tensor:
    def __init__(self, index, table, buffers):
        self.index = index
        shape = table.vector(0, "<i4")
        self.shape = [] if shape is None else [int(d) for d in shape]
        self.dtype = TENSOR_TYPES[table.scalar(1, "b")]
        self.name = table.string(3)
        self.sparsity = table.table(6)
        raw = buffers[table.scalar(2, "I")]
        # Raw stored bytes (None for activations); dense or the sparse values.
        self.data = None
        if raw is not None and len(raw) > 0:
            self.data = np.frombuffer(raw, dtype=self.dtype)
            if self.sparsity is None:
                self.data = self.data.reshape(self.shape)


class Operator:
    def __init__(self, table, opcodes):
        self.code = opcodes[table.scalar(0, "I")]
        self.name = OP_NAMES.get(self.code, "OP_%d" % self.code)
        self.inputs = [int(i) for i in table.vector(1, "<i4")]
        self.outputs = [int(i) for i in table.vector(2, "<i4")]
        self.options = table.table(4)  # a table whose fields depend on the op

    def option(self, index, fmt, default=0):
        if self.options is None:
            return default
        return self.options.scalar(index, fmt, default)


class TfliteModel:
    """The first subgraph of a TFLite file: tensors, operators, inputs, outputs."""

    def __init__(self, path):
        with open(path, "rb") as f:
            buf = f.read()
        if buf[4:8] != b"TFL3":
            raise ValueError("%s: not a TFLite file (no TFL3 identifier)" % path)
        model = Table(buf, struct.unpack_from("<I", buf, 0)[0])
        opcodes = []
        for code in model.tables(1):
            # The builtin code is the larger of the int8 deprecated field and the int32 one.
            opcodes.append(max(code.scalar(0, "b"), code.scalar(3, "i")))
        buffers = []
        for b in model.tables(4):
            data = b.vector(0, "u1")
            buffers.append(None if data is None else data.tobytes())
        subgraph = model.tables(2)[0]
        self.tensors = [Tensor(i, t, buffers) for i, t in enumerate(subgraph.tables(0))]
        self.inputs = [int(i) for i in subgraph.vector(1, "<i4")]
        self.outputs = [int(i) for i in subgraph.vector(2, "<i4")]
        self.operators = [Operator(t, opcodes) for t in subgraph.tables(3)]


def densify(tensor):
    """Dense values of a sparse constant tensor (TFLite SparsityParameters).

    traversal_order lists the stored dimensions (original ones, then block dimensions);
    each DimensionMetadata is DENSE (dense_size) or SPARSE_CSR (array_segments,
    array_indices). Values are stored in traversal order; block_map says which original
    dimension each block dimension subdivides.
    """
    sp = tensor.sparsity
    order = [int(d) for d in sp.vector(0, "<i4")]
    block_map_v = sp.vector(1, "<i4")
    block_map = [] if block_map_v is None else [int(d) for d in block_map_v]
    dims = sp.tables(2)
    rank = len(tensor.shape)
    # Sizes of every traversed dimension (original, then block).
    meta = []
    for d in dims:
        fmt = d.scalar(0, "b")
        if fmt == 0:
            meta.append(("dense", d.scalar(1, "i"), None, None))
        else:
            seg_type = d.scalar(2, "B")
            idx_type = d.scalar(4, "B")
            kinds = {1: "<i4", 2: "<u2", 3: "u1"}
            segs = d.table(3).vector(0, kinds[seg_type])
            idxs = d.table(5).vector(0, kinds[idx_type])
            meta.append(("sparse", None, segs.astype(np.int64), idxs.astype(np.int64)))
    # Block sizes: traversed dimension rank + k is a block of original dimension
    # block_map[k] (blocks are stored dense).
    block_size = [1] * rank
    for k, orig in enumerate(block_map):
        block_size[orig] = meta[order.index(rank + k)][1]
    dense = np.zeros(tensor.shape, dtype=tensor.dtype)
    values = tensor.data
    n_levels = len(order)
    coords = [0] * n_levels
    counter = [0]

    def visit(level, parent):
        kind, size, segs, idxs = meta[level]
        if kind == "dense":
            children = [(i, parent * size + i) for i in range(size)]
        else:
            children = [(int(idxs[j]), j) for j in range(int(segs[parent]), int(segs[parent + 1]))]
        for coord, pos in children:
            coords[order[level]] = coord
            if level + 1 == n_levels:
                index = coords[:rank]
                for k, orig in enumerate(block_map):
                    index[orig] = coords[orig] * block_size[orig] + coords[rank + k]
                dense[tuple(index)] = values[counter[0]]
                counter[0] += 1
            else:
                visit(level + 1, pos)

    visit(0, 0)
    if counter[0] != len(values):
        raise ValueError("tensor %s: densify used %d of %d values" % (tensor.name, counter[0], len(values)))
    return dense
