// C3D writer, from the format's public description (Motion Lab Systems, "The C3D File
// Format User Guide"): 512-byte blocks; block 1 the header, then the parameter section,
// then the 3D data as Intel (little-endian) float32. Layout written here:
//   header   word 1: parameter block (2) and key 0x50; 2: points; 3: analog (0);
//            4, 5: first and last frame; 6: max interpolation gap; 7-8: scale (float,
//            negative = float data); 9: first data block; 10: analog samples (0);
//            11-12: frame rate (float)
//   params   4-byte header (0x01, 0x50, block count, processor 84 = Intel), then groups
//            (negative id) and parameters (positive id), each with the offset to the next
//   data     per frame, per point: X, Y, Z, residual (float); residual -1 marks a gap
#include <algorithm>
#include <cmath>
#include <cstring>

#include "arco/export/export.h"

namespace arco::exporter {
namespace {

class Bytes {
 public:
  void I8(int v) { out_.push_back(static_cast<char>(static_cast<int8_t>(v))); }
  void I16(int v) {
    const uint16_t u = static_cast<uint16_t>(v);
    out_.push_back(static_cast<char>(u & 0xff));
    out_.push_back(static_cast<char>(u >> 8));
  }
  void F32(float v) {
    uint32_t u;
    std::memcpy(&u, &v, 4);
    for (int i = 0; i < 4; ++i) out_.push_back(static_cast<char>((u >> (8 * i)) & 0xff));
  }
  void Str(const std::string& s) { out_ += s; }
  std::string& str() { return out_; }

 private:
  std::string out_;
};

enum Type { kChar = -1, kInt16 = 2, kFloat = 4 };

struct Parameter {
  std::string name;
  Type type;
  std::vector<int> dims;
  std::string data;  // little-endian values
};

struct Group {
  std::string name;
  std::vector<Parameter> parameters;
};

Parameter Int16Param(const std::string& name, int v) {
  Bytes b;
  b.I16(v);
  return {name, kInt16, {}, b.str()};
}
Parameter FloatParam(const std::string& name, float v) {
  Bytes b;
  b.F32(v);
  return {name, kFloat, {}, b.str()};
}
// Strings padded with blanks to the longest: dims (length, count).
Parameter StringsParam(const std::string& name, const std::vector<std::string>& values) {
  size_t length = 1;
  for (const auto& v : values) length = std::max(length, v.size());
  std::string data;
  for (const auto& v : values) data += v + std::string(length - v.size(), ' ');
  return {name, kChar, {static_cast<int>(length), static_cast<int>(values.size())}, data};
}
Parameter StringParam(const std::string& name, const std::string& value) {
  return {name, kChar, {static_cast<int>(value.size())}, value};
}

std::string ParameterSection(const std::vector<Group>& groups, int blocks) {
  Bytes b;
  b.I8(1);
  b.I8(0x50);
  b.I8(blocks);
  b.I8(84);
  std::vector<size_t> last_offset_at;
  for (size_t g = 0; g < groups.size(); ++g) {
    const int id = static_cast<int>(g) + 1;
    const Group& group = groups[g];
    b.I8(static_cast<int>(group.name.size()));
    b.I8(-id);
    b.Str(group.name);
    b.I16(3);  // the offset word, then 0 description chars
    b.I8(0);
    for (const Parameter& p : group.parameters) {
      b.I8(static_cast<int>(p.name.size()));
      b.I8(id);
      b.Str(p.name);
      const size_t offset_at = b.str().size();
      b.I16(0);  // patched below
      b.I8(p.type);
      b.I8(static_cast<int>(p.dims.size()));
      for (int d : p.dims) b.I8(d);
      b.Str(p.data);
      b.I8(0);  // no description
      const size_t next = b.str().size();
      const int offset = static_cast<int>(next - offset_at);
      b.str()[offset_at] = static_cast<char>(offset & 0xff);
      b.str()[offset_at + 1] = static_cast<char>((offset >> 8) & 0xff);
      last_offset_at.push_back(offset_at);
    }
  }
  // The last parameter's offset 0 ends the section.
  if (!last_offset_at.empty()) {
    b.str()[last_offset_at.back()] = 0;
    b.str()[last_offset_at.back() + 1] = 0;
  }
  return b.str();
}

}  // namespace

StatusOr<std::string> C3dBytes(const ExportData& data) {
  const int64_t frames = data.frames();
  if (frames < 1 || frames > 65535 || data.points() > 32767) {
    return Status::Error("C3D holds 1 to 65535 frames and at most 32767 points (the result has " +
                         std::to_string(frames) + " frames, " + std::to_string(data.points()) +
                         " points)");
  }
  for (const auto& name : data.keypoint_names) {
    if (name.size() > 127) return Status::Error("C3D label longer than 127 characters: " + name);
  }
  // Parameter labels longer than 127 bytes cannot be dimensioned in one byte; the point
  // count per label array is a byte too, so labels go in chunks of 255 (LABELS, LABELS2).
  std::vector<Group> groups(2);
  groups[0].name = "POINT";
  auto& point = groups[0].parameters;
  point.push_back(Int16Param("USED", data.points()));
  point.push_back(FloatParam("SCALE", -1.0f));
  point.push_back(FloatParam("RATE", static_cast<float>(data.fps)));
  point.push_back(Int16Param("DATA_START", 0));  // patched once the size is known
  point.push_back(Int16Param("FRAMES", static_cast<int>(frames)));
  point.push_back(StringParam("UNITS", "mm"));
  for (int first = 0, chunk = 0; first < data.points(); first += 255, ++chunk) {
    const int last = std::min(data.points(), first + 255);
    std::vector<std::string> labels(data.keypoint_names.begin() + first,
                                    data.keypoint_names.begin() + last);
    const std::string suffix = chunk == 0 ? "" : std::to_string(chunk + 1);
    point.push_back(StringsParam("LABELS" + suffix, labels));
    point.push_back(
        StringsParam("DESCRIPTIONS" + suffix, std::vector<std::string>(labels.size(), "")));
  }
  groups[1].name = "ANALOG";
  groups[1].parameters.push_back(Int16Param("USED", 0));
  groups[1].parameters.push_back(FloatParam("RATE", static_cast<float>(data.fps)));

  const int param_blocks = static_cast<int>((ParameterSection(groups, 0).size() + 511) / 512);
  const int data_start = 2 + param_blocks;
  {
    Bytes b;
    b.I16(data_start);
    point[3].data = b.str();
  }
  std::string params = ParameterSection(groups, param_blocks);
  params.resize(static_cast<size_t>(param_blocks) * 512, '\0');

  Bytes header;
  header.I8(2);
  header.I8(0x50);
  header.I16(data.points());
  header.I16(0);
  header.I16(1);
  header.I16(static_cast<int>(frames));
  header.I16(0);
  header.F32(-1.0f);
  header.I16(data_start);
  header.I16(0);
  header.F32(static_cast<float>(data.fps));
  std::string out = header.str();
  out.resize(512, '\0');
  out += params;

  Bytes body;
  body.str().reserve(static_cast<size_t>(frames) * data.points() * 16);
  for (int64_t f = 0; f < frames; ++f) {
    for (int p = 0; p < data.points(); ++p) {
      const Eigen::Vector3d x = data.At(f, p);
      if (x.allFinite()) {
        body.F32(static_cast<float>(x[0]));
        body.F32(static_cast<float>(x[1]));
        body.F32(static_cast<float>(x[2]));
        body.F32(0.0f);
      } else {
        for (int k = 0; k < 3; ++k) body.F32(0.0f);
        body.F32(-1.0f);
      }
    }
  }
  std::string& d = body.str();
  d.resize((d.size() + 511) / 512 * 512, '\0');
  out += d;
  return out;
}

}  // namespace arco::exporter
