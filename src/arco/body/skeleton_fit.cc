#include "arco/body/skeleton_fit.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "arco/geometry/rotation.h"
#include "arco/util/dense_lm.h"
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

// The inverse of the Cholesky factor L (a = L L^T, lower triangular) of a symmetric 3x3
// matrix, from its lower triangle; false when a is not positive definite.
bool InverseCholesky3(const Eigen::Ref<const Eigen::MatrixXd>& a, Eigen::Matrix3d* inverse) {
  const double d0 = a(0, 0);
  if (!(d0 > 0)) return false;
  const double l00 = std::sqrt(d0);
  const double l10 = a(1, 0) / l00, l20 = a(2, 0) / l00;
  const double d1 = a(1, 1) - l10 * l10;
  if (!(d1 > 0)) return false;
  const double l11 = std::sqrt(d1);
  const double l21 = (a(2, 1) - l20 * l10) / l11;
  const double d2 = a(2, 2) - l20 * l20 - l21 * l21;
  if (!(d2 > 0)) return false;
  const double l22 = std::sqrt(d2);
  const double i00 = 1 / l00, i11 = 1 / l11, i22 = 1 / l22;
  const double i10 = -l10 * i00 * i11;
  const double i21 = -l21 * i11 * i22;
  const double i20 = -(l20 * i00 + l21 * i10) * i22;
  *inverse << i00, 0, 0, i10, i11, 0, i20, i21, i22;
  return true;
}

// One frame's robust least squares (see skeleton_fit.h): parameters x = (dp, delta[j] for
// the joints on a measured point's path), the keypoint of node i at
//   x_i = root + dp + sum over its path's bones (j -> c) of R_prev[j] Exp(delta[j]) offset[c],
// residuals sqrt(w) (x_i - measured) under a Huber loss plus a pull w_prior delta[j] of
// each rotation towards the previous frame. d x_i / d delta[j] =
// -R_prev[j] Exp(delta[j]) [offset[c]]x J_r(delta[j]) (geometry/rotation.h).
//
// Solved by Levenberg-Marquardt (util/dense_lm.h) on the dense normal equations (a few dozen
// parameters), with Ceres' trust-region rules (Marquardt's diagonal clamped to [1e-6, 1e32] and
// divided by the radius, starting at 1e4; radius update by the step quality, Nielsen's rule) and
// its stopping tests (function tolerance 1e-8 relative, gradient 1e-10, step 1e-8 relative), the
// Huber loss applied as Ceres does (residual and Jacobian scaled by sqrt(rho'), rho'' being 0 or
// negative). Until issue 28 part 3 this was a ceres::Problem built per frame with a sparse normal
// Cholesky: the same minimiser, but its set-up, sparse symbolic analysis and bookkeeping cost about
// ten times the arithmetic (a quarter of `arco run`'s CPU); joints moved by the solvers' tolerance
// (docs/performance.md).
class FrameSolver {
 public:
  struct Observation {
    int node = 0;
    Eigen::Vector3d measured;
    double sqrt_weight = 1;
  };

  FrameSolver(const std::vector<Node>& nodes, const SkeletonFitOptions& options)
      : nodes_(nodes),
        options_(options),
        paths_(nodes.size()),
        column_(nodes.size(), -1),
        turned_(nodes.size()),
        right_jacobian_(nodes.size()) {
    // Each node's path from the group's root, as (joint, child) bones in root-first order.
    for (size_t i = 0; i < nodes.size(); ++i) {
      for (int c = static_cast<int>(i); nodes[c].parent >= 0; c = nodes[c].parent) {
        paths_[i].push_back({nodes[c].parent, c});
      }
      std::reverse(paths_[i].begin(), paths_[i].end());
      max_path_ = std::max(max_path_, paths_[i].size());
    }
    blocks_.resize(max_path_ + 1);
    block_columns_.resize(max_path_ + 1);
  }

  // Solves one frame from delta = 0 and dp = 0; `rot` and `root` are the previous pose.
  void Solve(const std::vector<Observation>& observations,
             const std::vector<Eigen::Matrix3d>& rot,
             const Eigen::Vector3d& root,
             Eigen::Vector3d* dp,
             std::vector<Eigen::Vector3d>* delta) {
    observations_ = &observations;
    rot_ = &rot;
    root_ = root;
    std::fill(column_.begin(), column_.end(), -1);
    active_.clear();
    for (const Observation& o : observations) {
      for (const auto& [j, c] : paths_[o.node]) column_[j] = 0;
    }
    int size = 3;
    for (size_t j = 0; j < nodes_.size(); ++j) {
      if (column_[j] < 0) continue;
      column_[j] = size;
      size += 3;
      active_.push_back(static_cast<int>(j));
    }
    // The elimination order of SolveDamped: every joint before its ancestors (nodes come
    // after their parents), the root's translation last; each with its ancestors' columns.
    ancestors_.resize(active_.size());
    inverse_.resize(active_.size() + 1);
    for (size_t a = 0; a < active_.size(); ++a) {
      std::vector<int>& up = ancestors_[a];
      up.clear();
      for (int p = nodes_[active_[active_.size() - 1 - a]].parent; p >= 0; p = nodes_[p].parent) {
        up.push_back(column_[p]);
      }
      up.push_back(0);
    }
    x_.setZero(size);
    DenseLmOptions lm;
    lm.max_iterations = options_.max_iterations;
    lm.function_tolerance = 1e-8;
    lm.gradient_tolerance = 1e-10;
    lm.parameter_tolerance = 1e-8;
    lm.initial_radius = 1e4;
    lm_.Minimize(*this, lm, &x_);
    *dp = x_.head<3>();
    for (int j : active_) (*delta)[j] = x_.segment<3>(column_[j]);
  }

 public:  // DenseLm's problem
  // step = -a^-1 g by a block Cholesky factorisation in the elimination order set
  // up by Solve (false when a is not positive definite). A joint's delta shares
  // residuals only with its ancestors' and the root's (a point depends on the rotations
  // along its path), so eliminating every joint before its ancestors fills in no block
  // that is not already non-zero: about 10 3x3 block updates per joint instead of a
  // dense factorisation, whose dependent sums (a few dozen unknowns) took 70% of the fit.
  // Blocks are read and written at (later column, earlier column) in that order.
  bool SolveDamped(Eigen::MatrixXd& a, const Eigen::VectorXd& g, Eigen::VectorXd* step) {
    using Block = Eigen::Matrix3d;
    Eigen::VectorXd& x = *step;
    x = -g;
    const int joints = static_cast<int>(active_.size());
    auto column_of = [&](int e) { return e < joints ? column_[active_[joints - 1 - e]] : 0; };
    for (int e = 0; e <= joints; ++e) {
      const int c = column_of(e);
      if (!InverseCholesky3(a.block<3, 3>(c, c), &inverse_[e])) return false;
      if (e == joints) break;
      const std::vector<int>& up = ancestors_[e];
      for (int u : up) {  // L_uc = A_uc L_cc^-T
        const Block l = a.block<3, 3>(u, c) * inverse_[e].transpose();
        a.block<3, 3>(u, c) = l;
      }
      // Ancestors are listed nearest first, so up[i] comes later than up[k] for i > k.
      for (size_t k = 0; k < up.size(); ++k) {
        const Block lk = a.block<3, 3>(up[k], c).transpose();
        for (size_t i = k; i < up.size(); ++i) {
          a.block<3, 3>(up[i], up[k]).noalias() -= a.block<3, 3>(up[i], c) * lk;
        }
      }
    }
    for (int e = 0; e <= joints; ++e) {  // L y = -g
      const int c = column_of(e);
      const Eigen::Vector3d y = inverse_[e] * x.segment<3>(c);
      x.segment<3>(c) = y;
      if (e == joints) break;
      for (int u : ancestors_[e]) x.segment<3>(u).noalias() -= a.block<3, 3>(u, c) * y;
    }
    for (int e = joints; e >= 0; --e) {  // L^T x = y
      const int c = column_of(e);
      Eigen::Vector3d y = x.segment<3>(c);
      if (e < joints) {
        for (int u : ancestors_[e]) {
          y.noalias() -= a.block<3, 3>(u, c).transpose() * x.segment<3>(u);
        }
      }
      x.segment<3>(c) = inverse_[e].transpose() * y;
    }
    return true;
  }

  void Plus(const Eigen::VectorXd& x, const Eigen::VectorXd& step, Eigen::VectorXd* candidate) {
    *candidate = x + step;
  }

  // The cost 1/2 sum rho(|r|^2) + 1/2 |prior|^2 at x, with the Gauss-Newton matrix J^T J
  // and gradient J^T r of the loss-scaled residuals.
  double Evaluate(const Eigen::VectorXd& x, Eigen::MatrixXd* h, Eigen::VectorXd* g) {
    using Block = Eigen::Matrix3d;
    h->setZero(x.size(), x.size());
    g->setZero(x.size());
    for (int j : active_) {
      const Eigen::Vector3d d = x.segment<3>(column_[j]);
      turned_[j] = (*rot_)[j] * RotationFromAxisAngle(d);
      right_jacobian_[j] = RightJacobianSO3(d);
    }
    const double b = options_.robust_scale_mm;
    double cost = 0;
    for (const Observation& o : *observations_) {
      const auto& path = paths_[o.node];
      Eigen::Vector3d p = root_ + x.head<3>();
      for (const auto& [j, c] : path) p += turned_[j] * nodes_[c].offset;
      const Eigen::Vector3d r = o.sqrt_weight * (p - o.measured);
      const double s = r.squaredNorm();
      double rho1 = 1;  // rho'(s) of the Huber loss rho(s) = s, or 2 b sqrt(s) - b^2
      if (s > b * b) {
        const double e = std::sqrt(s);
        cost += 0.5 * (2 * b * e - b * b);
        rho1 = b / e;
      } else {
        cost += 0.5 * s;
      }
      size_t n = 0;
      blocks_[n] = o.sqrt_weight * Block::Identity();
      block_columns_[n++] = 0;
      for (const auto& [j, c] : path) {
        blocks_[n] =
            -o.sqrt_weight * turned_[j] * CrossMatrix(nodes_[c].offset) * right_jacobian_[j];
        block_columns_[n++] = column_[j];
      }
      for (size_t a = 0; a < n; ++a) {
        const Block ja = rho1 * blocks_[a].transpose();
        g->segment<3>(block_columns_[a]).noalias() += ja * r;
        for (size_t c = a; c < n; ++c) {
          const Block jj = ja * blocks_[c];
          h->block<3, 3>(block_columns_[a], block_columns_[c]) += jj;
          if (c != a) h->block<3, 3>(block_columns_[c], block_columns_[a]) += jj.transpose();
        }
      }
    }
    const double w2 = options_.rotation_prior_mm_per_rad * options_.rotation_prior_mm_per_rad;
    for (int j : active_) {
      const Eigen::Vector3d d = x.segment<3>(column_[j]);
      cost += 0.5 * w2 * d.squaredNorm();
      g->segment<3>(column_[j]) += w2 * d;
      h->block<3, 3>(column_[j], column_[j]).diagonal().array() += w2;
    }
    return cost;
  }

 private:
  const std::vector<Node>& nodes_;
  const SkeletonFitOptions& options_;
  std::vector<std::vector<std::pair<int, int>>> paths_;
  size_t max_path_ = 0;
  // Per frame.
  const std::vector<Observation>* observations_ = nullptr;
  const std::vector<Eigen::Matrix3d>* rot_ = nullptr;
  Eigen::Vector3d root_;
  std::vector<int> column_;  // first column of joint j's delta, -1 when not a parameter
  std::vector<int> active_;
  std::vector<std::vector<int>> ancestors_;  // per eliminated joint, ancestors' columns
  std::vector<Eigen::Matrix3d> inverse_;     // per eliminated block, L^-1 of its diagonal
  // Scratch, kept across frames.
  std::vector<Eigen::Matrix3d> turned_, right_jacobian_;
  std::vector<Eigen::Matrix3d> blocks_;
  std::vector<int> block_columns_;
  DenseLm<Eigen::VectorXd, Eigen::MatrixXd> lm_;
  Eigen::VectorXd x_;
};

Eigen::Matrix3d Exp(const Eigen::Vector3d& v) {
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
  FrameSolver solver(nodes, options);
  std::vector<FrameSolver::Observation> observations;
  std::vector<Eigen::Vector3d> delta(n, Eigen::Vector3d::Zero());
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
    observations.clear();
    for (int i : observed) {
      const int k = nodes[i].keypoint;
      observations.push_back({i, pts.At(f, k), std::sqrt(pts.Weight(f, k))});
    }
    Eigen::Vector3d dp = Eigen::Vector3d::Zero();
    std::fill(delta.begin(), delta.end(), Eigen::Vector3d::Zero());
    solver.Solve(observations, rot, root, &dp, &delta);
    root += dp;
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
