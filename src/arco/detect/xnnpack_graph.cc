#include "arco/detect/xnnpack_graph.h"

#include <onnx/onnx_pb.h>
#include <xnnpack.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <string>

namespace arco::detect {
namespace {

// XNNPACK is initialised once per process (its own tables of kernels for this CPU).
Status InitialiseXnnpack() {
  static std::once_flag once;
  static xnn_status status = xnn_status_success;
  std::call_once(once, [] { status = xnn_initialize(nullptr); });
  if (status != xnn_status_success) {
    return Status::Error("XNNPACK cannot run on this CPU (xnn_initialize failed)");
  }
  return Status::Ok();
}

// A value of the ONNX graph as XNNPACK holds it.
struct Value {
  uint32_t id = XNN_INVALID_VALUE_ID;
  std::vector<size_t> onnx_shape;  // ONNX's logical shape (NCHW when 4-D and nchw)
  bool nchw = false;               // a 4-D ONNX NCHW value, held as NHWC
};

std::vector<size_t> XnnDims(const Value& v) {
  if (!v.nchw) return v.onnx_shape;
  const std::vector<size_t>& s = v.onnx_shape;
  return {s[0], s[2], s[3], s[1]};
}

class Builder {
 public:
  Builder(const onnx::GraphProto& graph, std::vector<std::vector<float>>* constants)
      : graph_(graph), constants_(constants) {
    for (const onnx::TensorProto& t : graph.initializer()) initializers_[t.name()] = &t;
  }

  // The external values: each output is one value XNNPACK computes, or, for an output a
  // Concat computes (the detectors' anchors of each scale, Debian 12's XNNPACK has no
  // concatenation), the Concat's inputs, copied one after the other when run. Sets
  // (*parts)[k] to output k's external value ids; returns how many there are.
  StatusOr<uint32_t> Plan(const std::vector<std::string>& output_names,
                          std::vector<std::vector<uint32_t>>* parts) {
    // What each name is an alias of (Identity, and the Transpose to NHWC that the converter
    // puts before a graph output or a Reshape), so the value that is really computed is the
    // one declared external.
    std::map<std::string, const onnx::NodeProto*> producer;
    for (const onnx::NodeProto& node : graph_.node()) {
      if ((node.op_type() == "Identity" || node.op_type() == "Transpose") &&
          node.input_size() == 1 && node.output_size() == 1) {
        alias_[node.output(0)] = node.input(0);
      }
      for (const std::string& out : node.output()) producer[out] = &node;
    }
    const auto resolve = [&](std::string name) {
      while (alias_.count(name)) name = alias_[name];
      return name;
    };
    uint32_t next = 1;  // 0 is the input
    parts->assign(output_names.size(), {});
    for (size_t k = 0; k < output_names.size(); ++k) {
      const std::string name = resolve(output_names[k]);
      auto p = producer.find(name);
      if (p != producer.end() && p->second->op_type() == "Concat") {
        concat_outputs_.insert(name);
        for (const std::string& in : p->second->input()) {
          const std::string part = resolve(in);
          if (external_outputs_.count(part)) return Error("'" + part + "' feeds two outputs");
          external_outputs_[part] = next;
          part_names_.push_back(part);
          (*parts)[k].push_back(next++);
        }
      } else {
        external_outputs_[name] = next;
        part_names_.push_back(name);
        (*parts)[k].push_back(next++);
      }
    }
    return next - 1;
  }

  // Translates the graph; (*part_sizes)[i] is the element count of external value i + 1.
  Status Build(xnn_subgraph_t subgraph,
               int input_height,
               int input_width,
               std::vector<size_t>* part_sizes) {
    subgraph_ = subgraph;
    if (graph_.input_size() != 1)
      return Error("the graph has " + std::to_string(graph_.input_size()) + " inputs, not 1");
    Value input;
    input.onnx_shape = {1, 3, static_cast<size_t>(input_height), static_cast<size_t>(input_width)};
    input.nchw = true;
    ARCO_RETURN_IF_ERROR(Define(&input, 0, XNN_VALUE_FLAG_EXTERNAL_INPUT));
    values_[graph_.input(0).name()] = input;
    for (const onnx::NodeProto& node : graph_.node()) ARCO_RETURN_IF_ERROR(Translate(node));
    for (size_t i = 0; i < part_names_.size(); ++i) {
      auto it = values_.find(part_names_[i]);
      if (it == values_.end()) return Error("no node computes '" + part_names_[i] + "'");
      if (it->second.id != i + 1)
        return Error("the output '" + part_names_[i] + "' is not computed by a node of its own");
      size_t count = 1;
      for (size_t d : it->second.onnx_shape) count *= d;
      part_sizes->push_back(count);
    }
    return Status::Ok();
  }

 private:
  static Status Error(const std::string& what) { return Status::Error(what); }

  Status Check(xnn_status status, const onnx::NodeProto& node) {
    if (status == xnn_status_success) return Status::Ok();
    return Error("XNNPACK refused " + node.op_type() + " '" + node.name() + "' (status " +
                 std::to_string(static_cast<int>(status)) + ")");
  }

  // Defines `v` in the subgraph (as an external input or output, or internal).
  Status Define(Value* v, uint32_t external_id, uint32_t flags) {
    const std::vector<size_t> dims = XnnDims(*v);
    const xnn_status s = xnn_define_tensor_value(subgraph_,
                                                 xnn_datatype_fp32,
                                                 dims.size(),
                                                 dims.data(),
                                                 nullptr,
                                                 external_id,
                                                 flags,
                                                 &v->id);
    if (s != xnn_status_success) return Error("XNNPACK refused a value");
    return Status::Ok();
  }

  // The output value of `node`, defined with `onnx_shape`; external when it is a graph output.
  StatusOr<Value> Output(const onnx::NodeProto& node, std::vector<size_t> onnx_shape, bool nchw) {
    Value v;
    v.onnx_shape = std::move(onnx_shape);
    v.nchw = nchw && v.onnx_shape.size() == 4;
    auto ext = external_outputs_.find(node.output(0));
    if (ext != external_outputs_.end()) {
      ARCO_RETURN_IF_ERROR(Define(&v, ext->second, XNN_VALUE_FLAG_EXTERNAL_OUTPUT));
    } else {
      ARCO_RETURN_IF_ERROR(Define(&v, XNN_INVALID_VALUE_ID, 0));
    }
    values_[node.output(0)] = v;
    return v;
  }

  StatusOr<Value> In(const onnx::NodeProto& node, int k) {
    if (k >= node.input_size())
      return Error(node.op_type() + " '" + node.name() + "' lacks input " + std::to_string(k));
    auto it = values_.find(node.input(k));
    if (it == values_.end()) {
      return Error(node.op_type() + " '" + node.name() + "': input '" + node.input(k) +
                   "' is not computed before it");
    }
    return it->second;
  }

  // An initializer's values as floats (int64 constants converted), and its shape.
  StatusOr<std::vector<float>> Constant(const std::string& name,
                                        std::vector<int64_t>* shape = nullptr) {
    auto it = initializers_.find(name);
    if (it == initializers_.end()) return Error("'" + name + "' is not a constant");
    const onnx::TensorProto& t = *it->second;
    size_t count = 1;
    if (shape) shape->clear();
    for (int64_t d : t.dims()) {
      count *= static_cast<size_t>(d);
      if (shape) shape->push_back(d);
    }
    std::vector<float> out(count);
    if (t.data_type() == onnx::TensorProto::FLOAT) {
      if (!t.raw_data().empty()) {
        if (t.raw_data().size() != count * sizeof(float))
          return Error("'" + name + "' has a wrong size");
        std::memcpy(out.data(), t.raw_data().data(), count * sizeof(float));
      } else {
        if (static_cast<size_t>(t.float_data_size()) != count)
          return Error("'" + name + "' has a wrong size");
        std::copy(t.float_data().begin(), t.float_data().end(), out.begin());
      }
    } else if (t.data_type() == onnx::TensorProto::INT64) {
      std::vector<int64_t> v(count);
      if (!t.raw_data().empty()) {
        if (t.raw_data().size() != count * sizeof(int64_t))
          return Error("'" + name + "' has a wrong size");
        std::memcpy(v.data(), t.raw_data().data(), count * sizeof(int64_t));
      } else {
        if (static_cast<size_t>(t.int64_data_size()) != count)
          return Error("'" + name + "' has a wrong size");
        std::copy(t.int64_data().begin(), t.int64_data().end(), v.begin());
      }
      for (size_t i = 0; i < count; ++i) out[i] = static_cast<float>(v[i]);
    } else {
      return Error("'" + name + "' has data type " + std::to_string(t.data_type()));
    }
    return out;
  }

  // A static tensor holding `data` (kept alive for the runtime's life).
  StatusOr<uint32_t> Static(std::vector<float> data, const std::vector<size_t>& dims) {
    constants_->push_back(std::move(data));
    uint32_t id = XNN_INVALID_VALUE_ID;
    if (xnn_define_tensor_value(subgraph_,
                                xnn_datatype_fp32,
                                dims.size(),
                                dims.data(),
                                constants_->back().data(),
                                XNN_INVALID_VALUE_ID,
                                0,
                                &id) != xnn_status_success) {
      return Error("XNNPACK refused a constant");
    }
    return id;
  }

  static const onnx::AttributeProto* Attr(const onnx::NodeProto& node, const std::string& name) {
    for (const onnx::AttributeProto& a : node.attribute()) {
      if (a.name() == name) return &a;
    }
    return nullptr;
  }
  static std::vector<int64_t> Ints(const onnx::NodeProto& node,
                                   const std::string& name,
                                   std::vector<int64_t> fallback) {
    const onnx::AttributeProto* a = Attr(node, name);
    if (!a) return fallback;
    return std::vector<int64_t>(a->ints().begin(), a->ints().end());
  }
  static int64_t Int(const onnx::NodeProto& node, const std::string& name, int64_t fallback) {
    const onnx::AttributeProto* a = Attr(node, name);
    return a ? a->i() : fallback;
  }

  Status Translate(const onnx::NodeProto& node) {
    const std::string& op = node.op_type();
    const std::string where = op + " '" + node.name() + "'";
    if (node.output_size() != 1)
      return Error(where + " has " + std::to_string(node.output_size()) + " outputs");
    if (op == "Conv") return Conv(node, where);
    if (op == "Clip") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      float lo = -std::numeric_limits<float>::infinity(),
            hi = std::numeric_limits<float>::infinity();
      if (const onnx::AttributeProto* a = Attr(node, "min")) lo = a->f();
      if (const onnx::AttributeProto* a = Attr(node, "max")) hi = a->f();
      if (node.input_size() > 1 && !node.input(1).empty()) {
        ARCO_ASSIGN_OR_RETURN(std::vector<float> c, Constant(node.input(1)));
        lo = c.at(0);
      }
      if (node.input_size() > 2 && !node.input(2).empty()) {
        ARCO_ASSIGN_OR_RETURN(std::vector<float> c, Constant(node.input(2)));
        hi = c.at(0);
      }
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, x.onnx_shape, x.nchw));
      return Check(xnn_define_clamp(subgraph_, lo, hi, x.id, y.id, 0), node);
    }
    if (op == "Add") return Add(node, where);
    if (op == "Pad") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      if (node.input_size() < 2 || x.onnx_shape.size() != 4)
        return Error(where + ": only a 4-D Pad with constant pads");
      ARCO_ASSIGN_OR_RETURN(std::vector<float> pads, Constant(node.input(1)));
      float value = 0.0f;
      if (node.input_size() > 2 && !node.input(2).empty()) {
        ARCO_ASSIGN_OR_RETURN(std::vector<float> c, Constant(node.input(2)));
        value = c.at(0);
      }
      if (pads.size() != 8)
        return Error(where + ": pads of " + std::to_string(pads.size()) + " values");
      const onnx::AttributeProto* mode = Attr(node, "mode");
      if (mode && mode->s() != "constant") return Error(where + ": mode " + mode->s());
      std::vector<size_t> shape = x.onnx_shape;
      size_t pre[4], post[4];
      for (int a = 0; a < 4; ++a) {
        if (pads[a] < 0 || pads[4 + a] < 0) return Error(where + ": negative pads");
        shape[a] += static_cast<size_t>(pads[a] + pads[4 + a]);
      }
      // ONNX axis a of an NCHW value is XNNPACK axis {0, 3, 1, 2}[a].
      static const int kNhwcAxis[4] = {0, 3, 1, 2};
      for (int a = 0; a < 4; ++a) {
        const int b = x.nchw ? kNhwcAxis[a] : a;
        pre[b] = static_cast<size_t>(pads[a]);
        post[b] = static_cast<size_t>(pads[4 + a]);
      }
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, shape, x.nchw));
      return Check(xnn_define_static_constant_pad(subgraph_, pre, post, value, x.id, y.id, 0),
                   node);
    }
    if (op == "MaxPool") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      if (!x.nchw) return Error(where + ": input is not a 4-D NCHW value");
      const std::vector<int64_t> k = Ints(node, "kernel_shape", {});
      const std::vector<int64_t> s = Ints(node, "strides", {1, 1});
      const std::vector<int64_t> p = Ints(node, "pads", {0, 0, 0, 0});
      if (k.size() != 2 || s.size() != 2 || p.size() != 4 || Int(node, "ceil_mode", 0) != 0) {
        return Error(where + ": unsupported attributes");
      }
      std::vector<size_t> shape = x.onnx_shape;
      shape[2] =
          static_cast<size_t>((static_cast<int64_t>(shape[2]) + p[0] + p[2] - k[0]) / s[0] + 1);
      shape[3] =
          static_cast<size_t>((static_cast<int64_t>(shape[3]) + p[1] + p[3] - k[1]) / s[1] + 1);
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, shape, true));
      return Check(xnn_define_max_pooling_2d(subgraph_,
                                             p[0],
                                             p[3],
                                             p[2],
                                             p[1],
                                             k[0],
                                             k[1],
                                             s[0],
                                             s[1],
                                             1,
                                             1,
                                             -std::numeric_limits<float>::infinity(),
                                             std::numeric_limits<float>::infinity(),
                                             x.id,
                                             y.id,
                                             0),
                   node);
    }
    if (op == "GlobalAveragePool") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      if (!x.nchw) return Error(where + ": input is not a 4-D NCHW value");
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, {x.onnx_shape[0], x.onnx_shape[1], 1, 1}, true));
      return Check(xnn_define_global_average_pooling_2d(subgraph_,
                                                        -std::numeric_limits<float>::infinity(),
                                                        std::numeric_limits<float>::infinity(),
                                                        x.id,
                                                        y.id,
                                                        0),
                   node);
    }
    if (op == "Flatten") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      // NCHW and NHWC flatten alike only when H = W = 1 (after a global pool).
      if (Int(node, "axis", 1) != 1 || (x.nchw && (x.onnx_shape[2] != 1 || x.onnx_shape[3] != 1))) {
        return Error(where + ": only a Flatten of N x C x 1 x 1 along axis 1");
      }
      size_t count = 1;
      for (size_t i = 1; i < x.onnx_shape.size(); ++i) count *= x.onnx_shape[i];
      return Reshape(node, x, {x.onnx_shape[0], count});
    }
    if (op == "Reshape") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      if (x.nchw)
        return Error(where + ": a Reshape of an NCHW value (the converter transposes first)");
      if (node.input_size() < 2) return Error(where + ": no shape");
      ARCO_ASSIGN_OR_RETURN(std::vector<float> s, Constant(node.input(1)));
      size_t total = 1, known = 1;
      for (size_t d : x.onnx_shape) total *= d;
      int unknown = -1;
      std::vector<size_t> shape(s.size());
      for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == -1) {
          unknown = static_cast<int>(i);
        } else if (s[i] == 0) {
          shape[i] = x.onnx_shape.at(i);
          known *= shape[i];
        } else {
          shape[i] = static_cast<size_t>(s[i]);
          known *= shape[i];
        }
      }
      if (unknown >= 0) shape[unknown] = total / known;
      return Reshape(node, x, shape);
    }
    if (op == "Gemm") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      if (Int(node, "transB", 0) != 1 || Int(node, "transA", 0) != 0 || x.onnx_shape.size() != 2 ||
          (Attr(node, "alpha") && Attr(node, "alpha")->f() != 1.0f) ||
          (Attr(node, "beta") && Attr(node, "beta")->f() != 1.0f)) {
        return Error(where + ": only x * W^T + b");
      }
      std::vector<int64_t> wshape;
      ARCO_ASSIGN_OR_RETURN(std::vector<float> w, Constant(node.input(1), &wshape));
      if (wshape.size() != 2 || static_cast<size_t>(wshape[1]) != x.onnx_shape[1])
        return Error(where + ": weight shape");
      const size_t out = static_cast<size_t>(wshape[0]);
      ARCO_ASSIGN_OR_RETURN(uint32_t wid, Static(std::move(w), {out, x.onnx_shape[1]}));
      uint32_t bid = XNN_INVALID_VALUE_ID;
      if (node.input_size() > 2 && !node.input(2).empty()) {
        ARCO_ASSIGN_OR_RETURN(std::vector<float> b, Constant(node.input(2)));
        if (b.size() != out) return Error(where + ": bias size");
        ARCO_ASSIGN_OR_RETURN(bid, Static(std::move(b), {out}));
      }
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, {x.onnx_shape[0], out}, false));
      return Check(xnn_define_fully_connected(subgraph_,
                                              -std::numeric_limits<float>::infinity(),
                                              std::numeric_limits<float>::infinity(),
                                              x.id,
                                              wid,
                                              bid,
                                              y.id,
                                              0),
                   node);
    }
    if (op == "Sigmoid") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, x.onnx_shape, x.nchw));
      return Check(xnn_define_sigmoid(subgraph_, x.id, y.id, 0), node);
    }
    if (op == "PRelu") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      ARCO_ASSIGN_OR_RETURN(std::vector<float> slope, Constant(node.input(1)));
      if (!x.nchw || slope.size() != x.onnx_shape[1])
        return Error(where + ": only a per-channel slope");
      ARCO_ASSIGN_OR_RETURN(uint32_t sid, Static(std::move(slope), {x.onnx_shape[1]}));
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, x.onnx_shape, true));
      return Check(xnn_define_prelu(subgraph_, x.id, sid, y.id, 0), node);
    }
    if (op == "Slice") return ChannelSlice(node, where);
    if (op == "Concat") {
      // Only a Concat computing an output (Plan): its inputs are external values, laid one
      // after the other, which is the concatenation when every axis before it is 1.
      if (!concat_outputs_.count(node.output(0)))
        return Error(where + ": only a Concat computing an output");
      int64_t axis = Int(node, "axis", 0);
      std::vector<size_t> first;
      for (int k = 0; k < node.input_size(); ++k) {
        ARCO_ASSIGN_OR_RETURN(Value v, In(node, k));
        const int64_t rank = static_cast<int64_t>(v.onnx_shape.size());
        const int64_t a = axis < 0 ? axis + rank : axis;
        if (v.nchw || a < 0 || a >= rank)
          return Error(where + ": an axis or layout it cannot lay out");
        for (int64_t d = 0; d < a; ++d) {
          if (v.onnx_shape[d] != 1) return Error(where + ": a dimension before the axis is not 1");
        }
        std::vector<size_t> rest(v.onnx_shape.begin() + a + 1, v.onnx_shape.end());
        if (k == 0) first = rest;
        if (rest != first) return Error(where + ": inputs of different shapes");
      }
      return Status::Ok();
    }
    if (op == "Resize") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      const onnx::AttributeProto* mode = Attr(node, "mode");
      const onnx::AttributeProto* transform = Attr(node, "coordinate_transformation_mode");
      if (!x.nchw || !mode || mode->s() != "linear" || node.input_size() < 4) {
        return Error(where + ": only a bilinear Resize to constant sizes");
      }
      // TFLite's RESIZE_BILINEAR: half_pixel_centers is ONNX's half_pixel, XNNPACK's default;
      // without it, ONNX's asymmetric, XNNPACK's TensorFlow legacy mode.
      uint32_t flags = 0;
      const std::string t = transform ? transform->s() : "half_pixel";
      if (t == "asymmetric") {
        flags = XNN_FLAG_TENSORFLOW_LEGACY_MODE;
      } else if (t != "half_pixel") {
        return Error(where + ": coordinate_transformation_mode " + t);
      }
      ARCO_ASSIGN_OR_RETURN(std::vector<float> sizes, Constant(node.input(3)));
      if (sizes.size() != 4 || sizes[0] != x.onnx_shape[0] || sizes[1] != x.onnx_shape[1]) {
        return Error(where + ": only a resize of height and width");
      }
      const size_t h = static_cast<size_t>(sizes[2]), w = static_cast<size_t>(sizes[3]);
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, {x.onnx_shape[0], x.onnx_shape[1], h, w}, true));
      return Check(xnn_define_static_resize_bilinear_2d(subgraph_, h, w, x.id, y.id, flags), node);
    }
    if (op == "DepthToSpace") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      const onnx::AttributeProto* mode = Attr(node, "mode");
      const int64_t block = Int(node, "blocksize", 0);
      // TFLite's (NHWC) depth_to_space is ONNX's DCR mode, which is XNNPACK's.
      if (!x.nchw || block < 1 || (mode && mode->s() != "DCR") ||
          x.onnx_shape[1] % static_cast<size_t>(block * block) != 0) {
        return Error(where + ": only DCR mode");
      }
      const size_t b = static_cast<size_t>(block);
      const std::vector<size_t>& sh = x.onnx_shape;
      ARCO_ASSIGN_OR_RETURN(Value y,
                            Output(node, {sh[0], sh[1] / (b * b), sh[2] * b, sh[3] * b}, true));
      return Check(xnn_define_depth_to_space(subgraph_, x.id, y.id, static_cast<uint32_t>(b), 0),
                   node);
    }
    if ((op == "Identity" || op == "Transpose") && concat_outputs_.count(node.input(0))) {
      concat_outputs_.insert(node.output(0));  // the output's name for a concatenation
      return Status::Ok();
    }
    if (op == "Identity") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      values_[node.output(0)] = x;
      return Status::Ok();
    }
    if (op == "Transpose") {
      ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
      // NCHW -> NHWC of a value XNNPACK already holds as NHWC: the same memory, now plain.
      if (!x.nchw || Ints(node, "perm", {}) != std::vector<int64_t>{0, 2, 3, 1}) {
        return Error(where + ": only the transpose of a 4-D value to NHWC");
      }
      Value y = x;
      y.nchw = false;
      y.onnx_shape = XnnDims(x);
      values_[node.output(0)] = y;
      return Status::Ok();
    }
    return Error("operator " + where + " is not supported");
  }

  // The first channels of an NCHW value (hand_recrop's STRIDED_SLICE). Debian 12's XNNPACK
  // has no slice operator, so this is a 1 x 1 convolution whose weights pick channel c for
  // output c: each output is 1 * x_c plus zeros, exactly x_c.
  Status ChannelSlice(const onnx::NodeProto& node, const std::string& where) {
    ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
    if (!x.nchw || node.input_size() < 3)
      return Error(where + ": only a slice of an NCHW value's channels");
    ARCO_ASSIGN_OR_RETURN(std::vector<float> starts, Constant(node.input(1)));
    ARCO_ASSIGN_OR_RETURN(std::vector<float> ends, Constant(node.input(2)));
    std::vector<float> axes = {0}, steps = {1};
    if (node.input_size() > 3) {
      ARCO_ASSIGN_OR_RETURN(axes, Constant(node.input(3)));
    }
    if (node.input_size() > 4) {
      ARCO_ASSIGN_OR_RETURN(steps, Constant(node.input(4)));
    }
    const size_t in_c = x.onnx_shape[1];
    if (starts.size() != 1 || ends.size() != 1 || axes.size() != 1 || steps.size() != 1 ||
        axes[0] != 1 || starts[0] != 0 || steps[0] != 1 || ends[0] < 1) {
      return Error(where + ": only the first channels of an NCHW value");
    }
    const size_t out_c = std::min(in_c, static_cast<size_t>(ends[0]));
    std::vector<float> pick(out_c * in_c, 0.0f);
    for (size_t c = 0; c < out_c; ++c) pick[c * in_c + c] = 1.0f;
    ARCO_ASSIGN_OR_RETURN(uint32_t fid, Static(std::move(pick), {out_c, 1, 1, in_c}));
    std::vector<size_t> shape = x.onnx_shape;
    shape[1] = out_c;
    ARCO_ASSIGN_OR_RETURN(Value y, Output(node, shape, true));
    const float inf = std::numeric_limits<float>::infinity();
    return Check(xnn_define_convolution_2d(subgraph_,
                                           0,
                                           0,
                                           0,
                                           0,
                                           1,
                                           1,
                                           1,
                                           1,
                                           1,
                                           1,
                                           1,
                                           in_c,
                                           out_c,
                                           -inf,
                                           inf,
                                           x.id,
                                           fid,
                                           XNN_INVALID_VALUE_ID,
                                           y.id,
                                           0),
                 node);
  }

  Status Reshape(const onnx::NodeProto& node, const Value& x, std::vector<size_t> shape) {
    ARCO_ASSIGN_OR_RETURN(Value y, Output(node, shape, false));
    return Check(xnn_define_static_reshape(subgraph_, shape.size(), shape.data(), x.id, y.id, 0),
                 node);
  }

  Status Conv(const onnx::NodeProto& node, const std::string& where) {
    ARCO_ASSIGN_OR_RETURN(Value x, In(node, 0));
    if (!x.nchw) return Error(where + ": input is not a 4-D NCHW value");
    std::vector<int64_t> wshape;
    ARCO_ASSIGN_OR_RETURN(std::vector<float> w, Constant(node.input(1), &wshape));
    if (wshape.size() != 4)
      return Error(where + ": weight of rank " + std::to_string(wshape.size()));
    const size_t out_c = wshape[0], group_in = wshape[1], kh = wshape[2], kw = wshape[3];
    const std::vector<int64_t> s = Ints(node, "strides", {1, 1});
    const std::vector<int64_t> d = Ints(node, "dilations", {1, 1});
    const std::vector<int64_t> p = Ints(node, "pads", {0, 0, 0, 0});  // top, left, bottom, right
    const size_t groups = static_cast<size_t>(Int(node, "group", 1));
    const size_t in_c = x.onnx_shape[1];
    const bool depthwise = groups == in_c && group_in == 1 && groups > 1;
    if (s.size() != 2 || d.size() != 2 || p.size() != 4 || (groups != 1 && !depthwise) ||
        group_in * groups != in_c || out_c % groups != 0) {
      return Error(where + ": only a dense or a depthwise convolution");
    }
    if (const onnx::AttributeProto* a = Attr(node, "auto_pad"); a && a->s() != "NOTSET") {
      return Error(where + ": auto_pad " + a->s());
    }
    std::vector<float> bias(out_c, 0.0f);
    if (node.input_size() > 2 && !node.input(2).empty()) {
      ARCO_ASSIGN_OR_RETURN(bias, Constant(node.input(2)));
      if (bias.size() != out_c) return Error(where + ": bias size");
    }
    std::vector<size_t> shape = x.onnx_shape;
    shape[1] = out_c;
    shape[2] = static_cast<size_t>(
        (static_cast<int64_t>(shape[2]) + p[0] + p[2] - d[0] * (kh - 1) - 1) / s[0] + 1);
    shape[3] = static_cast<size_t>(
        (static_cast<int64_t>(shape[3]) + p[1] + p[3] - d[1] * (kw - 1) - 1) / s[1] + 1);
    ARCO_ASSIGN_OR_RETURN(uint32_t bid, Static(std::move(bias), {out_c}));
    const float lo = -std::numeric_limits<float>::infinity(),
                hi = std::numeric_limits<float>::infinity();
    if (depthwise) {
      // Depthwise: ONNX O x 1 x KH x KW -> XNNPACK 1 x KH x KW x O.
      std::vector<float> filter(w.size());
      for (size_t o = 0; o < out_c; ++o)
        for (size_t i = 0; i < kh * kw; ++i) filter[i * out_c + o] = w[o * kh * kw + i];
      ARCO_ASSIGN_OR_RETURN(uint32_t fid, Static(std::move(filter), {1, kh, kw, out_c}));
      ARCO_ASSIGN_OR_RETURN(Value y, Output(node, shape, true));
      return Check(xnn_define_depthwise_convolution_2d(subgraph_,
                                                       p[0],
                                                       p[3],
                                                       p[2],
                                                       p[1],
                                                       kh,
                                                       kw,
                                                       s[0],
                                                       s[1],
                                                       d[0],
                                                       d[1],
                                                       out_c / in_c,
                                                       in_c,
                                                       lo,
                                                       hi,
                                                       x.id,
                                                       fid,
                                                       bid,
                                                       y.id,
                                                       0),
                   node);
    }
    // ONNX O x I x KH x KW -> XNNPACK O x KH x KW x I.
    std::vector<float> filter(w.size());
    for (size_t o = 0; o < out_c; ++o)
      for (size_t i = 0; i < in_c; ++i)
        for (size_t k = 0; k < kh * kw; ++k)
          filter[(o * kh * kw + k) * in_c + i] = w[(o * in_c + i) * kh * kw + k];
    ARCO_ASSIGN_OR_RETURN(uint32_t fid, Static(std::move(filter), {out_c, kh, kw, in_c}));
    ARCO_ASSIGN_OR_RETURN(Value y, Output(node, shape, true));
    return Check(xnn_define_convolution_2d(subgraph_,
                                           p[0],
                                           p[3],
                                           p[2],
                                           p[1],
                                           kh,
                                           kw,
                                           s[0],
                                           s[1],
                                           d[0],
                                           d[1],
                                           1,
                                           in_c,
                                           out_c,
                                           lo,
                                           hi,
                                           x.id,
                                           fid,
                                           bid,
                                           y.id,
                                           0),
                 node);
  }

  // Add (NumPy broadcasting, as XNNPACK has it), of values or of a constant.
  Status Add(const onnx::NodeProto& node, const std::string& where) {
    if (node.input_size() != 2) return Error(where + ": not two inputs");
    std::vector<Value> in;
    for (int k = 0; k < node.input_size(); ++k) {
      if (initializers_.count(node.input(k))) {
        std::vector<int64_t> cshape;
        ARCO_ASSIGN_OR_RETURN(std::vector<float> c, Constant(node.input(k), &cshape));
        Value v;
        v.onnx_shape.assign(cshape.begin(), cshape.end());
        v.nchw = v.onnx_shape.size() == 4;
        std::vector<float> data = c;
        if (v.nchw) {  // NCHW constant -> NHWC
          const size_t C = v.onnx_shape[1], H = v.onnx_shape[2], W = v.onnx_shape[3];
          for (size_t ch = 0; ch < C; ++ch)
            for (size_t i = 0; i < H * W; ++i) data[i * C + ch] = c[ch * H * W + i];
        }
        ARCO_ASSIGN_OR_RETURN(v.id, Static(std::move(data), XnnDims(v)));
        in.push_back(v);
      } else {
        ARCO_ASSIGN_OR_RETURN(Value v, In(node, k));
        in.push_back(v);
      }
    }
    if (in[1].nchw != in[0].nchw || in[1].onnx_shape.size() != in[0].onnx_shape.size()) {
      return Error(where + ": inputs of different layouts");
    }
    std::vector<size_t> shape = in[0].onnx_shape;
    for (size_t a = 0; a < shape.size(); ++a) shape[a] = std::max(shape[a], in[1].onnx_shape[a]);
    ARCO_ASSIGN_OR_RETURN(Value y, Output(node, shape, in[0].nchw));
    const float inf = std::numeric_limits<float>::infinity();
    return Check(xnn_define_add2(subgraph_, -inf, inf, in[0].id, in[1].id, y.id, 0), node);
  }

  const onnx::GraphProto& graph_;
  std::vector<std::vector<float>>* constants_;
  std::map<std::string, const onnx::TensorProto*> initializers_;
  std::map<std::string, Value> values_;
  std::map<std::string, uint32_t> external_outputs_;
  std::map<std::string, std::string> alias_;
  std::set<std::string> concat_outputs_;
  std::vector<std::string> part_names_;  // external value i + 1
  xnn_subgraph_t subgraph_ = nullptr;
};

}  // namespace

struct XnnpackGraph::Impl {
  std::vector<std::vector<float>> constants;  // static tensors; outlive the runtime
  pthreadpool_t pool = nullptr;               // none: the calling thread only
  xnn_runtime_t runtime = nullptr;
  std::vector<float> input;  // H x W x 3, with XNNPACK's extra bytes
  std::vector<xnn_external_value> externals;
  // The parts of an output a Concat computes, and where each goes.
  struct Copy {
    size_t part, output, offset;
  };
  std::vector<std::vector<float>> parts;
  std::vector<Copy> copies;
  ~Impl() {
    if (runtime) xnn_delete_runtime(runtime);
    if (pool) pthreadpool_destroy(pool);
  }
};

XnnpackGraph::XnnpackGraph() : impl_(std::make_unique<Impl>()) {}
XnnpackGraph::~XnnpackGraph() = default;

StatusOr<std::unique_ptr<XnnpackGraph>> XnnpackGraph::Load(
    const std::string& onnx_path,
    const std::vector<std::string>& output_names,
    int input_height,
    int input_width,
    int num_threads,
    const OutputCheck& check) {
  ARCO_RETURN_IF_ERROR(InitialiseXnnpack());
  onnx::ModelProto model;
  {
    std::ifstream in(onnx_path, std::ios::binary);
    if (!in || !model.ParseFromIstream(&in)) {
      return Status::Error(onnx_path +
                           ": cannot read the ONNX model (not an ONNX protobuf); run "
                           "scripts/setup to fetch and convert it again");
    }
  }
  std::vector<std::string> graph_outputs;
  for (const onnx::ValueInfoProto& output : model.graph().output())
    graph_outputs.push_back(output.name());
  ARCO_RETURN_IF_ERROR(check(graph_outputs));
  std::unique_ptr<XnnpackGraph> graph(new XnnpackGraph());
  if (num_threads > 1) {
    graph->impl_->pool = pthreadpool_create(static_cast<size_t>(num_threads));
    if (!graph->impl_->pool) return Status::Error(onnx_path + ": cannot start XNNPACK's threads");
  }
  Builder builder(model.graph(), &graph->impl_->constants);
  std::vector<std::vector<uint32_t>> parts;
  StatusOr<uint32_t> externals = builder.Plan(output_names, &parts);
  if (!externals.ok()) return Status::Error(onnx_path + ": " + externals.status().message());
  xnn_subgraph_t subgraph = nullptr;
  if (xnn_create_subgraph(*externals + 1, 0, &subgraph) != xnn_status_success) {
    return Status::Error(onnx_path + ": XNNPACK cannot create a subgraph");
  }
  std::vector<size_t> part_sizes;
  Status built = builder.Build(subgraph, input_height, input_width, &part_sizes);
  if (built.ok()) {
    // The pool's threads yield after each pass instead of spinning for the next: a tracker
    // crops and decodes between passes, and spinning threads would take its cores.
    if (xnn_create_runtime_v2(
            subgraph, graph->impl_->pool, XNN_FLAG_YIELD_WORKERS, &graph->impl_->runtime) !=
        xnn_status_success) {
      built = Status::Error("XNNPACK cannot create the runtime");
    }
  }
  xnn_delete_subgraph(subgraph);
  if (!built.ok()) return Status::Error(onnx_path + ": " + built.message());
  Impl& impl = *graph->impl_;
  impl.input.assign(
      static_cast<size_t>(input_height) * input_width * 3 + XNN_EXTRA_BYTES / sizeof(float), 0.0f);
  impl.externals.push_back({0, impl.input.data()});
  impl.parts.resize(part_sizes.size());
  for (size_t k = 0; k < parts.size(); ++k) {
    size_t count = 0;
    for (uint32_t id : parts[k]) count += part_sizes[id - 1];
    graph->outputs_.emplace_back(count, 0.0f);
  }
  for (size_t k = 0; k < parts.size(); ++k) {
    size_t offset = 0;
    for (uint32_t id : parts[k]) {
      float* data = graph->outputs_[k].data();
      if (parts[k].size() > 1) {  // written apart, then laid one after the other
        impl.parts[id - 1].assign(part_sizes[id - 1], 0.0f);
        impl.copies.push_back({id - 1, k, offset});
        data = impl.parts[id - 1].data();
      }
      impl.externals.push_back({id, data});
      offset += part_sizes[id - 1];
    }
  }
  if (xnn_setup_runtime(impl.runtime, impl.externals.size(), impl.externals.data()) !=
      xnn_status_success) {
    return Status::Error(onnx_path + ": XNNPACK cannot set up the runtime");
  }
  return graph;
}

Status XnnpackGraph::Run(const float* input_nhwc) {
  const size_t count = impl_->input.size() - XNN_EXTRA_BYTES / sizeof(float);
  std::memcpy(impl_->input.data(), input_nhwc, count * sizeof(float));
  if (xnn_invoke_runtime(impl_->runtime) != xnn_status_success) {
    return Status::Error("XNNPACK failed to run the graph");
  }
  for (const Impl::Copy& c : impl_->copies) {
    const std::vector<float>& part = impl_->parts[c.part];
    std::memcpy(outputs_[c.output].data() + c.offset, part.data(), part.size() * sizeof(float));
  }
  return Status::Ok();
}

}  // namespace arco::detect
