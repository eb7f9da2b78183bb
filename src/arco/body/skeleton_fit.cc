#include "arco/body/skeleton_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "arco/geometry/rotation.h"
#include "arco/util/parallel.h"
#include "arco/util/stats.h"

namespace arco::body {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One group's subtree: the skeleton's joints of the group, in the skeleton's order.
struct Node {
  int keypoint = -1;           // index in the points; -1 for a midpoint
  int mid_a = -1, mid_b = -1;  // a midpoint's keypoints
  int parent = -1;             // index in the subtree; -1 for the group's root
  std::vector<int> children;   // indices in the subtree
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // rest offset in the parent's frame
};

class Points {
 public:
  Points(const NpyArray<double>& p, const NpyArray<double>& w) : p_(p), w_(w) {}
  Eigen::Vector3d At(int64_t f, int k) const {
    if (k < 0) return Eigen::Vector3d::Constant(kNaN);
    if (!w_.shape.empty() && !(w_.at(f, k) > 0)) return Eigen::Vector3d::Constant(kNaN);
    return {p_.at(f, k, 0), p_.at(f, k, 1), p_.at(f, k, 2)};
  }
  double Weight(int64_t f, int k) const { return w_.shape.empty() ? 1.0 : w_.at(f, k); }
  Eigen::Vector3d Target(const Node& n, int64_t f) const {
    if (n.keypoint >= 0) return At(f, n.keypoint);
    return 0.5 * (At(f, n.mid_a) + At(f, n.mid_b));
  }

 private:
  const NpyArray<double>& p_;
  const NpyArray<double>& w_;
};

// The nodes measured at least once whose parents are kept, re-indexed: a keypoint the
// capture never has (a body imported without feet, say) and everything hanging from it stay
// as they are (missing) instead of keeping the rest of the group from being fitted.
std::vector<Node> MeasuredSubtree(const std::vector<Node>& nodes,
                                  const Points& pts,
                                  int64_t frames) {
  std::vector<int> index(nodes.size(), -1);
  std::vector<Node> kept;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const Node& n = nodes[i];
    if (n.parent >= 0 && index[static_cast<size_t>(n.parent)] < 0) continue;
    if (n.parent < 0 && !kept.empty()) continue;
    bool measured = false;
    for (int64_t f = 0; f < frames && !measured; ++f) measured = pts.Target(n, f).allFinite();
    if (!measured) continue;
    Node copy = n;
    copy.children.clear();
    copy.parent = n.parent >= 0 ? index[static_cast<size_t>(n.parent)] : -1;
    index[i] = static_cast<int>(kept.size());
    if (copy.parent >= 0) kept[static_cast<size_t>(copy.parent)].children.push_back(index[i]);
    kept.push_back(copy);
  }
  if (!kept.empty() && nodes.front().parent < 0 && index[0] != 0) kept.clear();
  return kept;
}

// Rest offsets of the children of node j (false when a bone is never measured).
bool RestOffsets(std::vector<Node>& nodes, int j, const Points& pts, int64_t frames) {
  const std::vector<int>& ch = nodes[static_cast<size_t>(j)].children;
  if (ch.empty()) return true;
  std::vector<double> lengths(ch.size());
  for (size_t i = 0; i < ch.size(); ++i) {
    std::vector<double> l;
    for (int64_t f = 0; f < frames; ++f) {
      const double d = (pts.Target(nodes[ch[i]], f) - pts.Target(nodes[j], f)).norm();
      if (std::isfinite(d)) l.push_back(d);
    }
    if (l.empty()) return false;
    lengths[i] = Median(l);
  }
  // The frames where every child is measured, as offsets from the joint.
  std::vector<std::vector<Eigen::Vector3d>> sets;
  for (int64_t f = 0; f < frames; ++f) {
    std::vector<Eigen::Vector3d> s;
    const Eigen::Vector3d x = pts.Target(nodes[j], f);
    for (int c : ch) {
      const Eigen::Vector3d d = pts.Target(nodes[c], f) - x;
      if (d.allFinite()) s.push_back(d);
    }
    if (s.size() == ch.size()) sets.push_back(std::move(s));
  }
  if (sets.empty()) return false;
  std::vector<Eigen::Vector3d> shape = sets.front();
  if (ch.size() > 1) {
    // Twice: align every frame to the shape, take the component-wise median.
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<Eigen::Vector3d> next(ch.size());
      std::vector<std::vector<double>> comp(ch.size() * 3);
      for (const auto& s : sets) {
        const Eigen::Matrix3d r = KabschRotation(s, shape);
        for (size_t i = 0; i < ch.size(); ++i) {
          const Eigen::Vector3d a = r * s[i];
          for (int k = 0; k < 3; ++k) comp[3 * i + k].push_back(a[k]);
        }
      }
      for (size_t i = 0; i < ch.size(); ++i) {
        for (int k = 0; k < 3; ++k) next[i][k] = Median(comp[3 * i + k]);
      }
      shape = next;
    }
  }
  for (size_t i = 0; i < ch.size(); ++i) {
    if (!(shape[i].norm() > 1e-9)) return false;
    nodes[ch[i]].offset = shape[i].normalized() * lengths[i];
  }
  // A midpoint joint sits exactly between its two keypoints' joints.
  const Node& n = nodes[static_cast<size_t>(j)];
  if (n.keypoint < 0) {
    int a = -1, b = -1;
    for (int c : ch) {
      if (nodes[c].keypoint == n.mid_a) a = c;
      if (nodes[c].keypoint == n.mid_b) b = c;
    }
    if (a >= 0 && b >= 0) {
      const Eigen::Vector3d half = 0.5 * (nodes[a].offset - nodes[b].offset);
      nodes[a].offset = half;
      nodes[b].offset = -half;
    }
  }
  return true;
}

// The weighted distance of one keypoint from forward kinematics along its path:
// x = root + sum over the path's bones (j -> c) of R_prev[j] * exp(delta[j]) * offset[c].
// Parameter blocks: the root's translation, then each path joint's delta (3 each).
// Analytic Jacobians, d x / d delta[j] = -R_prev[j] exp(delta[j]) [offset[c]]x J_r(delta[j])
// (geometry/rotation.h): the same derivatives as automatic differentiation, which took
// ceil(3 (1 + path) / 4) passes of jets per evaluation and a quarter of `arco run`'s CPU.
class PointCost final : public ceres::CostFunction {
 public:
  PointCost(const Eigen::Vector3d& base,
            std::vector<Eigen::Matrix3d> rotations,
            std::vector<Eigen::Vector3d> offsets,
            const Eigen::Vector3d& measured,
            double sqrt_weight)
      : base_(base),
        rotations_(std::move(rotations)),
        offsets_(std::move(offsets)),
        measured_(measured),
        sqrt_weight_(sqrt_weight) {
    set_num_residuals(3);
    mutable_parameter_block_sizes()->assign(offsets_.size() + 1, 3);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    Eigen::Vector3d x = base_ + Eigen::Map<const Eigen::Vector3d>(p[0]);
    for (size_t i = 0; i < offsets_.size(); ++i) {
      const Eigen::Vector3d delta = Eigen::Map<const Eigen::Vector3d>(p[i + 1]);
      const Eigen::Matrix3d turned = rotations_[i] * RotationFromAxisAngle(delta);
      x += turned * offsets_[i];
      if (jacobians != nullptr && jacobians[i + 1] != nullptr) {
        Eigen::Map<RowMajor3> jacobian(jacobians[i + 1]);
        jacobian = -sqrt_weight_ * turned * CrossMatrix(offsets_[i]) * RightJacobianSO3(delta);
      }
    }
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = sqrt_weight_ * (x - measured_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<RowMajor3> jacobian(jacobians[0]);
      jacobian = sqrt_weight_ * Eigen::Matrix3d::Identity();
    }
    return true;
  }

 private:
  Eigen::Vector3d base_;  // previous root position
  std::vector<Eigen::Matrix3d> rotations_;
  std::vector<Eigen::Vector3d> offsets_;
  Eigen::Vector3d measured_;
  double sqrt_weight_ = 1.0;
};

struct PriorCost {
  double weight;
  template <typename T>
  bool operator()(const T* d, T* r) const {
    for (int a = 0; a < 3; ++a) r[a] = T(weight) * d[a];
    return true;
  }
};

Eigen::Matrix3d Exp(const std::array<double, 3>& d) {
  const Eigen::Vector3d v(d[0], d[1], d[2]);
  const double angle = v.norm();
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

// Fits one group on frames [start, end), started cold at `start`; fills frames
// [write_from, end) of `out` and appends their residuals to `residuals`.
void FitGroup(const std::vector<Node>& nodes,
              const Points& pts,
              int64_t start,
              int64_t write_from,
              int64_t end,
              const SkeletonFitOptions& options,
              NpyArray<double>& out,
              std::vector<double>& residuals) {
  const int n = static_cast<int>(nodes.size());
  std::vector<Eigen::Matrix3d> rot(n, Eigen::Matrix3d::Identity());
  Eigen::Vector3d root = Eigen::Vector3d::Zero();
  bool initialised = false;
  std::vector<Eigen::Vector3d> fk(n);
  auto forward = [&](const std::vector<Eigen::Matrix3d>& r, const Eigen::Vector3d& p0) {
    for (int i = 0; i < n; ++i) {
      fk[i] = nodes[i].parent < 0
                  ? p0
                  : Eigen::Vector3d(fk[nodes[i].parent] + r[nodes[i].parent] * nodes[i].offset);
    }
  };
  for (int64_t f = start; f < end; ++f) {
    std::vector<int> observed;
    for (int i = 0; i < n; ++i) {
      if (nodes[i].keypoint >= 0 && pts.At(f, nodes[i].keypoint).allFinite()) observed.push_back(i);
    }
    if (observed.empty()) continue;  // nothing to fit: the frame keeps its (missing) points
    if (!initialised) {
      // The tree fit (as the BVH exporter's): each joint turned to its measured children.
      const Eigen::Vector3d r0 = pts.Target(nodes[0], f);
      root = r0.allFinite() ? r0 : pts.At(f, nodes[observed[0]].keypoint);
      for (int i = 0; i < n; ++i) {
        std::vector<Eigen::Vector3d> rest, measured;
        const Eigen::Vector3d x = pts.Target(nodes[i], f);
        for (int c : nodes[i].children) {
          const Eigen::Vector3d d = pts.Target(nodes[c], f) - x;
          if (!d.allFinite()) continue;
          rest.push_back(nodes[c].offset);
          measured.push_back(d);
        }
        if (rest.size() >= 2) {
          rot[i] = KabschRotation(rest, measured);
        } else if (rest.size() == 1) {
          rot[i] = Eigen::Quaterniond::FromTwoVectors(rest[0], measured[0]).toRotationMatrix();
        } else if (nodes[i].parent >= 0) {
          rot[i] = rot[nodes[i].parent];
        }
      }
      initialised = true;
    }
    std::array<double, 3> dp = {0, 0, 0};
    std::vector<std::array<double, 3>> delta(n, {0, 0, 0});
    ceres::Problem::Options po;
    po.loss_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    problem.AddParameterBlock(dp.data(), 3);
    for (int i : observed) {
      std::vector<double*> blocks = {dp.data()};
      std::vector<Eigen::Matrix3d> rotations;
      std::vector<Eigen::Vector3d> offsets;
      std::vector<int> path;
      for (int c = i; nodes[c].parent >= 0; c = nodes[c].parent) path.push_back(c);
      std::reverse(path.begin(), path.end());
      for (int c : path) {
        const int j = nodes[c].parent;
        rotations.push_back(rot[j]);
        offsets.push_back(nodes[c].offset);
        blocks.push_back(delta[j].data());
      }
      auto* fn = new PointCost(root,
                               std::move(rotations),
                               std::move(offsets),
                               pts.At(f, nodes[i].keypoint),
                               std::sqrt(pts.Weight(f, nodes[i].keypoint)));
      problem.AddResidualBlock(fn, new ceres::HuberLoss(options.robust_scale_mm), blocks);
    }
    for (int j = 0; j < n; ++j) {
      if (nodes[j].children.empty() || !problem.HasParameterBlock(delta[j].data())) continue;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost, 3, 3>(
                                   new PriorCost{options.rotation_prior_mm_per_rad}),
                               nullptr,
                               delta[j].data());
    }
    ceres::Solver::Options so;
    // Each point's residual depends on the root and the rotations along its path only, so
    // J^T J is mostly zeros: the sparse Cholesky took 25% less time than the dense one on
    // the same iterates (58 s take, docs/performance.md). Tolerances 1e-8 instead of 1e-10
    // took 8.6 instead of 12.7 iterations per frame and moved no joint by more than
    // 0.05 mm (p99 0.002 mm; arco eval unchanged to 0.01 mm).
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    // Eigen's sparse Cholesky: at these sizes (a few dozen parameters) its per-frame
    // analysis costs less than CHOLMOD's; `arco refine --mode arco --threads 1` on the
    // one-minute take 2.7 -> 2.5 s of CPU, joints moved by at most 1e-8 mm.
    if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE))
      so.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
    so.max_num_iterations = options.max_iterations;
    so.num_threads = 1;
    so.function_tolerance = 1e-8;
    so.gradient_tolerance = 1e-10;
    so.parameter_tolerance = 1e-8;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    root += Eigen::Vector3d(dp[0], dp[1], dp[2]);
    for (int j = 0; j < n; ++j) rot[j] = rot[j] * Exp(delta[j]);
    forward(rot, root);
    if (f < write_from) continue;  // a warm-up frame
    for (int i = 0; i < n; ++i) {
      const int k = nodes[i].keypoint;
      if (k < 0) continue;
      const Eigen::Vector3d m = pts.At(f, k);
      if (m.allFinite()) residuals.push_back((fk[i] - m).norm());
      for (int a = 0; a < 3; ++a) out.at(f, k, a) = fk[i][a];
    }
  }
}

}  // namespace

Status SkeletonFitOptions::Validate() const {
  if (!(robust_scale_mm > 0)) return Status::Error("robust_scale_mm must be > 0");
  if (!(rotation_prior_mm_per_rad >= 0)) {
    return Status::Error("rotation_prior_mm_per_rad must be >= 0");
  }
  if (max_iterations < 1) return Status::Error("max_iterations must be >= 1");
  if (chunk_frames < 1) return Status::Error("chunk_frames must be >= 1");
  if (warmup_frames < 0) return Status::Error("warmup_frames must be >= 0");
  if (num_threads < 0) return Status::Error("num_threads must be >= 0 (0 = all cores)");
  return Status::Ok();
}

StatusOr<SkeletonFitResult> FitSkeleton(const NpyArray<double>& points_mm,
                                        const std::vector<std::string>& names,
                                        const NpyArray<double>& weights,
                                        const SkeletonFitOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (points_mm.shape.size() != 3 || points_mm.shape[2] != 3 ||
      points_mm.shape[1] != static_cast<int64_t>(names.size())) {
    return Status::Error("FitSkeleton: points must be (F, names, 3)");
  }
  const int64_t frames = points_mm.shape[0];
  if (!weights.shape.empty() && weights.shape != std::vector<int64_t>{frames, points_mm.shape[1]}) {
    return Status::Error("FitSkeleton: weights must be (F, P) or empty");
  }
  auto find = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  };
  const Points pts(points_mm, weights);
  const std::vector<SkeletonJoint>& skeleton = WholeBodySkeleton();
  SkeletonFitResult result;
  result.points_mm = points_mm;
  // The groups' subtrees and rest offsets (serial: medians over the whole take), then
  // every (group, chunk) fitted independently.
  struct Group {
    JointGroup group;
    std::vector<Node> nodes;
  };
  std::vector<Group> groups;
  for (JointGroup group : options.groups) {
    std::vector<Node> nodes;
    std::vector<int> index(skeleton.size(), -1);
    bool complete = true;
    for (size_t s = 0; s < skeleton.size(); ++s) {
      const SkeletonJoint& j = skeleton[s];
      if (j.group != group) continue;
      Node node;
      if (!j.keypoint.empty()) {
        node.keypoint = find(j.keypoint);
        complete = complete && node.keypoint >= 0;
      } else {
        node.mid_a = find(j.mid_a);
        node.mid_b = find(j.mid_b);
        complete = complete && node.mid_a >= 0 && node.mid_b >= 0;
      }
      node.parent = j.parent >= 0 ? index[static_cast<size_t>(j.parent)] : -1;
      if (node.parent < 0 && !nodes.empty()) {
        return Status::Error("FitSkeleton: a joint group has two roots");  // a broken skeleton
      }
      index[s] = static_cast<int>(nodes.size());
      if (node.parent >= 0) nodes[static_cast<size_t>(node.parent)].children.push_back(index[s]);
      nodes.push_back(node);
    }
    if (!complete || nodes.empty()) continue;
    nodes = MeasuredSubtree(nodes, pts, frames);
    if (nodes.empty()) continue;  // the group's root never measured: the group stays raw
    for (int j = 0; j < static_cast<int>(nodes.size()) && complete; ++j) {
      complete = RestOffsets(nodes, j, pts, frames);
    }
    if (!complete) continue;  // a bone never measured: the group stays raw
    groups.push_back({group, std::move(nodes)});
  }
  const int64_t chunk = options.chunk_frames;
  const int64_t chunks = (frames + chunk - 1) / chunk;
  const int64_t items = static_cast<int64_t>(groups.size()) * chunks;
  std::vector<std::vector<double>> residuals(static_cast<size_t>(items));
  // Each item writes only its group's keypoints on its own frames of result.points_mm.
  ParallelFor(
      items,
      options.num_threads,
      [&](int64_t item, int) {
        const int64_t c = item % chunks;
        FitGroup(groups[static_cast<size_t>(item / chunks)].nodes,
                 pts,
                 std::max<int64_t>(0, c * chunk - options.warmup_frames),
                 c * chunk,
                 std::min(frames, (c + 1) * chunk),
                 options,
                 result.points_mm,
                 residuals[static_cast<size_t>(item)]);
      },
      1);
  for (size_t g = 0; g < groups.size(); ++g) {
    std::vector<double> all;
    for (int64_t c = 0; c < chunks; ++c) {
      const std::vector<double>& r = residuals[g * static_cast<size_t>(chunks) + c];
      all.insert(all.end(), r.begin(), r.end());
    }
    result.fitted_groups.push_back(groups[g].group);
    result.median_residual_mm.push_back(all.empty() ? 0.0 : Median(all));
  }
  return result;
}

}  // namespace arco::body
