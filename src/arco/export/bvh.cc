// BVH writer: one skeleton for the body and both hands, fitted per frame.
//
// Skeleton: body/skeleton.h's WholeBodySkeleton (joint names are arco's keypoint names,
// plus two joints at midpoints, hips (the root: position + rotation channels) and neck),
// the tree `arco run` fits to the arco method's body and right hand, so that this fit
// reproduces those points exactly.
// Then two rigid roots: "instrument" (scroll_top, nut_l/r, bridge_l/r, tail_gut, end_pin and
// the strings' ends present in the layout) and "bow" (frog, tip), each at its points'
// centroid with the points as child joints, fitted per frame as a rigid body (Kabsch; the
// bow, a line, by the smallest rotation). The face and the contact points are not joints.
//
// Fit. Rest pose: the first frame where every joint exists, each bone rescaled to its
// median length over the frames (so the rest offsets are the result's median lengths).
// Per frame, down the tree from the root at its measured position: a joint with one child
// turns by the smallest rotation (from its parent's orientation) that points the bone at
// the child's point; a joint with several children takes the rotation that best aligns
// their rest offsets with the measured ones (Kabsch, SVD); a leaf keeps its parent's
// orientation. Each joint's fitted position is its parent's fitted position plus the
// rotated rest offset (except the hand wrists, below), so the error is the bone-length change plus,
// below a branching joint, the non-rigidity of the branch. A joint whose target points are missing
// keeps its previous local rotation. The hand wrists (left_hand_wrist, right_hand_wrist) have
// position channels too, placing each hand at its measured wrist: the body's wrist and the
// hand's wrist are two estimates of one joint (often from different detectors or, for
// arco's left hand, the fitted hand model), and the hand is not made to carry the
// forearm's error. Position channels are the local translation in the parent's frame and
// replace the OFFSET (the root's OFFSET is 0). Rotations are written as Z, X, Y Euler angles in
// degrees (R = Rz Rx Ry, the usual BVH order).
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "arco/body/skeleton.h"
#include "arco/export/export.h"
#include "arco/geometry/rotation.h"
#include "arco/util/stats.h"

namespace arco::exporter {
namespace {

struct Joint {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  int keypoint = -1;           // index in the data; -1 for a midpoint joint
  int mid_a = -1, mid_b = -1;  // midpoint joints: the two keypoints
  Eigen::Vector3d offset_mm = Eigen::Vector3d::Zero();  // rest offset from the parent
  int group = 0;            // for the residual summary: 0 body, 1 left hand, 2 right hand
  bool positioned = false;  // has position channels: placed at its point
};

class Skeleton {
 public:
  std::vector<Joint> joints;

  int Add(const std::string& name, int parent, int keypoint, int group = 0) {
    Joint j;
    j.name = name;
    j.parent = parent;
    j.keypoint = keypoint;
    j.group = group;
    joints.push_back(j);
    const int id = static_cast<int>(joints.size()) - 1;
    if (parent >= 0) joints[parent].children.push_back(id);
    return id;
  }
};

// The skeleton of body/skeleton.h (the one definition, shared with `arco run`'s skeleton
// fit) on the data's keypoints.
StatusOr<Skeleton> BuildSkeleton(const ExportData& data) {
  std::string missing;
  auto kp = [&](const std::string& name) {
    const int i = data.Find(name);
    if (i < 0) missing += (missing.empty() ? "" : ", ") + name;
    return i;
  };
  Skeleton s;
  for (const body::SkeletonJoint& b : body::WholeBodySkeleton()) {
    const int id = s.Add(b.name, b.parent, -1, static_cast<int>(b.group));
    Joint& j = s.joints[static_cast<size_t>(id)];
    if (!b.keypoint.empty()) {
      j.keypoint = kp(b.keypoint);
    } else {
      j.mid_a = kp(b.mid_a);
      j.mid_b = kp(b.mid_b);
    }
    j.positioned = b.positioned;
  }
  if (!missing.empty()) {
    return Status::Error("BVH needs the body and both hands; the result's points lack " + missing);
  }
  return s;
}

// Target position of joint j in frame f (NaN when missing).
Eigen::Vector3d Target(const ExportData& data, const Joint& j, int64_t f) {
  if (j.keypoint >= 0) return data.At(f, j.keypoint);
  return 0.5 * (data.At(f, j.mid_a) + data.At(f, j.mid_b));
}

void AppendF(std::string& out, const char* fmt, double v) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof(buf), fmt, v);
  out.append(buf, n);
}

void WriteJoint(const Skeleton& s, int id, int depth, std::string& out) {
  const Joint& j = s.joints[id];
  const std::string pad(2 * depth, ' ');
  out += pad + (j.parent < 0 ? "ROOT " : "JOINT ") + j.name + "\n" + pad + "{\n";
  out += pad + "  OFFSET";
  for (int k = 0; k < 3; ++k) AppendF(out, " %.6f", j.offset_mm[k]);
  out += "\n" + pad +
         (j.parent < 0 || j.positioned
              ? "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
              : "  CHANNELS 3 Zrotation Xrotation Yrotation\n");
  for (int c : j.children) WriteJoint(s, c, depth + 1, out);
  if (j.children.empty()) {
    // An end a quarter of the incoming bone further on, so importers give the leaf a bone.
    const Eigen::Vector3d end = 0.25 * j.offset_mm;
    out += pad + "  End Site\n" + pad + "  {\n" + pad + "    OFFSET";
    for (int k = 0; k < 3; ++k) AppendF(out, " %.6f", end[k]);
    out += "\n" + pad + "  }\n";
  }
  out += pad + "}\n";
}

// A rigid body as a second (third) root: the instrument's points, the bow's frog and tip.
// The root sits at the points' centroid; each point is a child joint at its rest offset.
struct RigidRoot {
  std::string name;
  std::vector<int> keypoints;
  std::vector<Eigen::Vector3d> rest;  // offsets from the rest centroid
  std::vector<std::vector<double>> errors;
};

std::optional<RigidRoot> MakeRigidRoot(const ExportData& data,
                                       const std::string& name,
                                       const std::vector<std::string>& points) {
  RigidRoot r;
  r.name = name;
  for (const auto& p : points) {
    const int i = data.Find(p);
    if (i >= 0) r.keypoints.push_back(i);
  }
  if (r.keypoints.size() < 2) return std::nullopt;
  for (int64_t f = 0; f < data.frames(); ++f) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    bool all = true;
    for (int k : r.keypoints) {
      all = all && data.At(f, k).allFinite();
      centroid += data.At(f, k);
    }
    if (!all) continue;
    centroid /= r.keypoints.size();
    for (int k : r.keypoints) r.rest.push_back(data.At(f, k) - centroid);
    r.errors.resize(r.keypoints.size());
    return r;
  }
  return std::nullopt;
}

// Rotation and centroid of frame f (the previous ones held when fewer than two points, or
// for a body of more than two, fewer than three, exist).
void FitRigidRootFrame(const ExportData& data,
                       int64_t f,
                       RigidRoot& root,
                       Eigen::Matrix3d& rotation,
                       Eigen::Vector3d& centroid) {
  std::vector<Eigen::Vector3d> rest, measured;
  Eigen::Vector3d rest_mean = Eigen::Vector3d::Zero(), mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < root.keypoints.size(); ++i) {
    const Eigen::Vector3d x = data.At(f, root.keypoints[i]);
    if (!x.allFinite()) continue;
    rest.push_back(root.rest[i]);
    measured.push_back(x);
    rest_mean += root.rest[i];
    mean += x;
  }
  const size_t needed = root.keypoints.size() == 2 ? 2 : 3;
  if (rest.size() >= needed) {
    rest_mean /= rest.size();
    mean /= rest.size();
    for (size_t i = 0; i < rest.size(); ++i) {
      rest[i] -= rest_mean;
      measured[i] -= mean;
    }
    rotation = rest.size() == 2 ? Eigen::Matrix3d(Eigen::Quaterniond::FromTwoVectors(
                                      rest[1] - rest[0], measured[1] - measured[0]))
                                : KabschRotation(rest, measured);
    centroid = mean - rotation * rest_mean;
  }
  for (size_t i = 0; i < root.keypoints.size(); ++i) {
    const Eigen::Vector3d x = data.At(f, root.keypoints[i]);
    if (x.allFinite()) root.errors[i].push_back((centroid + rotation * root.rest[i] - x).norm());
  }
}

void WriteRigidRoot(const ExportData& data, const RigidRoot& r, std::string& out) {
  out += "ROOT " + r.name + "\n{\n  OFFSET 0.000000 0.000000 0.000000\n";
  out += "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n";
  for (size_t i = 0; i < r.keypoints.size(); ++i) {
    out += "  JOINT " + data.keypoint_names[r.keypoints[i]] + "\n  {\n    OFFSET";
    for (int k = 0; k < 3; ++k) AppendF(out, " %.6f", r.rest[i][k]);
    out += "\n    CHANNELS 3 Zrotation Xrotation Yrotation\n";
    out += "    End Site\n    {\n      OFFSET 0.000000 0.000000 1.000000\n    }\n  }\n";
  }
  out += "}\n";
}

}  // namespace

StatusOr<BvhExport> ExportBvh(const ExportData& data) {
  ARCO_ASSIGN_OR_RETURN(Skeleton skeleton, BuildSkeleton(data));
  auto& joints = skeleton.joints;
  const int n = static_cast<int>(joints.size());
  const int64_t frames = data.frames();

  // Rest pose: the first frame with every joint, bones scaled to their median lengths.
  int64_t rest = -1;
  for (int64_t f = 0; f < frames && rest < 0; ++f) {
    bool all = true;
    for (const Joint& j : joints) all = all && Target(data, j, f).allFinite();
    if (all) rest = f;
  }
  if (rest < 0) return Status::Error("BVH: no frame has every body and hand joint");
  for (int i = 1; i < n; ++i) {
    Joint& j = joints[i];
    std::vector<double> lengths;
    for (int64_t f = 0; f < frames; ++f) {
      const double l = (Target(data, j, f) - Target(data, joints[j.parent], f)).norm();
      if (std::isfinite(l)) lengths.push_back(l);
    }
    const Eigen::Vector3d d = Target(data, j, rest) - Target(data, joints[j.parent], rest);
    const double length = Median(lengths);
    j.offset_mm =
        d.norm() > 1e-12 ? Eigen::Vector3d(d.normalized() * length) : Eigen::Vector3d::Zero();
  }

  // Per frame: world rotation and fitted position of every joint (parents first: the
  // joints are stored in depth-first order).
  std::vector<Eigen::Matrix3d> local(n, Eigen::Matrix3d::Identity()), world(n);
  std::vector<Eigen::Vector3d> fitted(n);
  // Local translations: the rest offsets, and the last measured one of a positioned joint.
  std::vector<Eigen::Vector3d> translation(n);
  for (int i = 0; i < n; ++i) translation[i] = joints[i].offset_mm;
  Eigen::Vector3d root_position = Target(data, joints[0], rest);
  std::vector<std::vector<double>> errors(n);
  // The instrument and the bow: rigid roots after the skeleton.
  std::vector<RigidRoot> rigid;
  {
    std::vector<std::string> instrument;
    for (const char* p :
         {"scroll_top", "nut_l", "nut_r", "bridge_l", "bridge_r", "tail_gut", "end_pin"}) {
      instrument.push_back(p);
    }
    for (int s = 1; s <= 4; ++s) {
      instrument.push_back("string" + std::to_string(s) + "_top");
      instrument.push_back("string" + std::to_string(s) + "_bottom");
    }
    for (auto r : {MakeRigidRoot(data, "instrument", instrument),
                   MakeRigidRoot(data, "bow", {"frog", "tip"})}) {
      if (r) rigid.push_back(std::move(*r));
    }
  }
  std::vector<Eigen::Matrix3d> rigid_rotation(rigid.size(), Eigen::Matrix3d::Identity());
  std::vector<Eigen::Vector3d> rigid_centroid(rigid.size(), Eigen::Vector3d::Zero());
  std::string motion;
  motion.reserve(static_cast<size_t>(frames) * (3 * n + 3) * 12);
  for (int64_t f = 0; f < frames; ++f) {
    const Eigen::Vector3d root_target = Target(data, joints[0], f);
    if (root_target.allFinite()) root_position = root_target;
    for (int i = 0; i < n; ++i) {
      const Joint& j = joints[i];
      const Eigen::Matrix3d parent_world =
          j.parent < 0 ? Eigen::Matrix3d::Identity() : world[j.parent];
      fitted[i] = j.parent < 0 ? root_position
                               : Eigen::Vector3d(fitted[j.parent] + parent_world * translation[i]);
      if (j.positioned) {
        const Eigen::Vector3d t = Target(data, j, f);
        if (t.allFinite()) {
          fitted[i] = t;
          translation[i] = parent_world.transpose() * (t - fitted[j.parent]);
        }
      }
      std::vector<Eigen::Vector3d> rest_offsets, measured;
      for (int c : j.children) {
        const Eigen::Vector3d t = Target(data, joints[c], f);
        if (!t.allFinite() || joints[c].offset_mm.norm() < 1e-9) continue;
        rest_offsets.push_back(joints[c].offset_mm);
        measured.push_back(t - fitted[i]);
      }
      if (j.children.size() == 1 && measured.size() == 1 && measured[0].norm() > 1e-9) {
        const Eigen::Vector3d from = parent_world * rest_offsets[0];
        const Eigen::Matrix3d turn =
            Eigen::Quaterniond::FromTwoVectors(from, measured[0]).toRotationMatrix();
        world[i] = turn * parent_world;
        local[i] = parent_world.transpose() * world[i];
      } else if (j.children.size() > 1 && measured.size() >= 2) {
        world[i] = KabschRotation(rest_offsets, measured);
        local[i] = parent_world.transpose() * world[i];
      } else {
        world[i] = parent_world * local[i];  // a leaf (identity) or a held rotation
      }
      const Eigen::Vector3d target = Target(data, j, f);
      if (j.keypoint >= 0 && target.allFinite()) errors[i].push_back((fitted[i] - target).norm());
    }
    for (int k = 0; k < 3; ++k) AppendF(motion, k == 0 ? "%.6f" : " %.6f", root_position[k]);
    for (int i = 0; i < n; ++i) {
      if (i > 0 && joints[i].positioned) {
        for (int k = 0; k < 3; ++k) AppendF(motion, " %.6f", translation[i][k]);
      }
      const Eigen::Vector3d zxy = local[i].eulerAngles(2, 0, 1) * (180.0 / M_PI);
      for (int k = 0; k < 3; ++k) AppendF(motion, " %.6f", zxy[k]);
    }
    for (size_t r = 0; r < rigid.size(); ++r) {
      FitRigidRootFrame(data, f, rigid[r], rigid_rotation[r], rigid_centroid[r]);
      for (int k = 0; k < 3; ++k) AppendF(motion, " %.6f", rigid_centroid[r][k]);
      const Eigen::Vector3d zxy = rigid_rotation[r].eulerAngles(2, 0, 1) * (180.0 / M_PI);
      for (int k = 0; k < 3; ++k) AppendF(motion, " %.6f", zxy[k]);
      for (size_t i = 0; i < rigid[r].keypoints.size(); ++i) motion += " 0 0 0";
    }
    motion += '\n';
  }

  BvhExport out;
  std::vector<double> pooled[3];
  for (int i = 0; i < n; ++i) {
    if (joints[i].keypoint < 0) continue;
    BvhJointResidual r;
    r.name = joints[i].name;
    r.frames = static_cast<int>(errors[i].size());
    if (r.frames > 0) {
      r.median_mm = Median(errors[i]);
      r.max_mm = *std::max_element(errors[i].begin(), errors[i].end());
    }
    auto& group = pooled[joints[i].group];
    group.insert(group.end(), errors[i].begin(), errors[i].end());
    out.residuals.push_back(r);
  }
  for (const RigidRoot& r : rigid) {
    for (size_t i = 0; i < r.keypoints.size(); ++i) {
      BvhJointResidual res;
      res.name = data.keypoint_names[r.keypoints[i]];
      res.frames = static_cast<int>(r.errors[i].size());
      if (res.frames > 0) {
        res.median_mm = Median(r.errors[i]);
        res.max_mm = *std::max_element(r.errors[i].begin(), r.errors[i].end());
      }
      out.residuals.push_back(res);
    }
  }
  double* medians[3] = {&out.body_median_mm, &out.left_hand_median_mm, &out.right_hand_median_mm};
  for (int g = 0; g < 3; ++g) *medians[g] = pooled[g].empty() ? 0 : Median(pooled[g]);

  std::string& text = out.text;
  text = "HIERARCHY\n";
  text += "# arco export (" + data.method +
          "): units mm, arco's world axes; joints named by "
          "arco keypoint names (hips, neck: midpoints); docs/export.md\n";
  char line[256];
  std::snprintf(line,
                sizeof(line),
                "# fit residual median mm: body %.4f left hand %.4f right hand %.4f\n",
                out.body_median_mm,
                out.left_hand_median_mm,
                out.right_hand_median_mm);
  text += line;
  for (const auto& r : out.residuals) {
    std::snprintf(line,
                  sizeof(line),
                  "# residual_mm %s median %.6f max %.6f frames %d\n",
                  r.name.c_str(),
                  r.median_mm,
                  r.max_mm,
                  r.frames);
    text += line;
  }
  WriteJoint(skeleton, 0, 0, text);
  for (const RigidRoot& r : rigid) WriteRigidRoot(data, r, text);
  text += "MOTION\nFrames: " + std::to_string(frames) + "\n";
  AppendF(text, "Frame Time: %.8f\n", 1.0 / data.fps);
  text += motion;
  return out;
}

}  // namespace arco::exporter
