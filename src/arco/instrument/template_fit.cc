#include "arco/instrument/template_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "arco/instrument/rigid_align.h"
#include "arco/util/parallel.h"
#include "arco/util/stats.h"

namespace arco {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Percent(double fraction) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << 100.0 * fraction << "%";
  return s.str();
}

// Nut-centre to bridge-centre distance, NaN when a point is missing.
double NutBridge(const InstrumentModel& model, const Eigen::Matrix3Xd& m) {
  const Eigen::Vector3d nut = 0.5 * (m.col(model.nut_l()) + m.col(model.nut_r()));
  const Eigen::Vector3d bridge = 0.5 * (m.col(model.bridge_l()) + m.col(model.bridge_r()));
  return nut.allFinite() && bridge.allFinite() ? (nut - bridge).norm() : kNaN;
}

// Step 2 of the header comment.
int ChooseReferenceFrame(const std::vector<Eigen::Matrix3Xd>& pts, const std::vector<int>& rigid) {
  const int num_frames = static_cast<int>(pts.size());
  std::vector<std::pair<int, int>> pairs;
  for (size_t a = 0; a < rigid.size(); ++a) {
    for (size_t b = a + 1; b < rigid.size(); ++b) pairs.emplace_back(rigid[a], rigid[b]);
  }
  std::vector<double> median_distance(pairs.size());
  std::vector<double> values;
  for (size_t p = 0; p < pairs.size(); ++p) {
    values.clear();
    for (const Eigen::Matrix3Xd& m : pts) {
      const double d = (m.col(pairs[p].first) - m.col(pairs[p].second)).norm();
      if (std::isfinite(d)) values.push_back(d);
    }
    median_distance[p] = Median(values);
  }
  int max_count = 0;
  std::vector<int> counts(num_frames, 0);
  for (int f = 0; f < num_frames; ++f) {
    for (int k : rigid) counts[f] += pts[f].col(k).allFinite() ? 1 : 0;
    max_count = std::max(max_count, counts[f]);
  }
  if (max_count < 3) return -1;
  int best = -1;
  double best_score = std::numeric_limits<double>::infinity();
  for (int f = 0; f < num_frames; ++f) {
    if (counts[f] != max_count) continue;
    double sum = 0;
    int n = 0;
    for (size_t p = 0; p < pairs.size(); ++p) {
      const double d = (pts[f].col(pairs[p].first) - pts[f].col(pairs[p].second)).norm();
      if (std::isfinite(d) && std::isfinite(median_distance[p])) {
        sum += std::abs(d - median_distance[p]);
        ++n;
      }
    }
    const double score = n > 0 ? sum / n : std::numeric_limits<double>::infinity();
    if (best < 0 || score < best_score) {
      best = f;
      best_score = score;
    }
  }
  return best;
}

// Per-coordinate median of the inlier observations of each rigid keypoint, mapped into the
// template frame (step 3).
Eigen::Matrix3Xd UpdateTemplate(const std::vector<Eigen::Matrix3Xd>& pts,
                                const std::vector<RigidAlignment>& align,
                                const std::vector<uint8_t>& used,
                                const std::vector<int>& rigid,
                                int min_observations) {
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Constant(3, pts.front().cols(), kNaN);
  std::vector<double> coords[3];
  for (int k : rigid) {
    for (auto& c : coords) c.clear();
    for (size_t f = 0; f < pts.size(); ++f) {
      if (!used[f] || !(align[f].inlier_mask & (1u << k))) continue;
      const Eigen::Vector3d p = align[f].target_from_source.rotation.transpose() *
                                (pts[f].col(k) - align[f].target_from_source.translation);
      for (int a = 0; a < 3; ++a) coords[a].push_back(p(a));
    }
    if (static_cast<int>(coords[0].size()) < min_observations) continue;
    for (int a = 0; a < 3; ++a) out(a, k) = Median(coords[a]);
  }
  return out;
}

double MaxChange(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  double change = 0;
  for (int k = 0; k < a.cols(); ++k) {
    const bool fa = a.col(k).allFinite(), fb = b.col(k).allFinite();
    if (fa != fb) return std::numeric_limits<double>::infinity();
    if (fa) change = std::max(change, (a.col(k) - b.col(k)).norm());
  }
  return change;
}

}  // namespace

StatusOr<InstrumentFit> FitInstrument(const InstrumentModel& model,
                                      const std::vector<Eigen::Matrix3Xd>& keypoints_in_world,
                                      const std::vector<FrontHint>& hints,
                                      const InstrumentFitOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const int num_frames = static_cast<int>(keypoints_in_world.size());
  const int num_keypoints = static_cast<int>(model.keypoint_names().size());
  for (const Eigen::Matrix3Xd& m : keypoints_in_world) {
    if (m.cols() != num_keypoints) {
      throw std::invalid_argument("FitInstrument: a frame has " + std::to_string(m.cols()) +
                                  " keypoint columns; " + model.name() + " has " +
                                  std::to_string(num_keypoints));
    }
  }
  if (hints.size() != 1 && static_cast<int>(hints.size()) != num_frames) {
    throw std::invalid_argument("FitInstrument: give one front hint or one per frame");
  }
  if (num_frames == 0) return Status::Error("instrument fit: the clip has no frames");

  // 1. Scale from the median nut-bridge distance.
  std::vector<double> distances;
  std::vector<double> magnitudes;
  for (const Eigen::Matrix3Xd& m : keypoints_in_world) {
    const double d = NutBridge(model, m);
    if (!std::isfinite(d)) continue;
    distances.push_back(d);
    magnitudes.push_back(m.col(model.bridge_l()).cwiseAbs().maxCoeff());
  }
  if (distances.empty()) {
    return Status::Error(
        "instrument fit: no frame has all four of nut_l, nut_r, bridge_l, "
        "bridge_r");
  }
  const double median_distance = Median(distances);
  if (!(median_distance > 1e-9 * std::max(1e-300, Median(magnitudes)))) {
    return Status::Error("instrument fit: nut and bridge coincide (median distance " +
                         std::to_string(median_distance) + ")");
  }
  const double length_mm = model.string_length_mm();
  double u = options.scale == InstrumentFitOptions::Scale::kFromStringLength
                 ? median_distance / length_mm
             : options.scale == InstrumentFitOptions::Scale::kGiven ? options.world_units_per_mm
                                                                    : 1.0;
  const std::vector<int>& rigid = model.rigid_keypoints();
  std::vector<Eigen::Matrix3Xd> pts(num_frames, Eigen::Matrix3Xd::Constant(3, num_keypoints, kNaN));
  for (int f = 0; f < num_frames; ++f) {
    for (int k : rigid) {
      if (keypoints_in_world[f].col(k).allFinite())
        pts[f].col(k) = keypoints_in_world[f].col(k) / u;
    }
  }

  // 2.-3. Initial template, then alternate alignment and robust update.
  const int reference = ChooseReferenceFrame(pts, rigid);
  if (reference < 0) return Status::Error("instrument fit: no frame has three keypoints");
  Eigen::Matrix3Xd shape = pts[reference];
  InstrumentFit fit;
  InstrumentFitSummary& summary = fit.summary;
  summary.num_frames = num_frames;
  std::vector<RigidAlignment> align(num_frames);
  std::vector<uint8_t> used(num_frames, 0);
  double gate = options.max_point_gate_mm;
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    summary.iterations = iter + 1;
    summary.point_gate_mm = gate;
    ParallelFor(num_frames, options.num_threads, [&](int64_t f, int) {
      align[f] = AlignRigidRobust(shape, pts[f], gate, options.min_spread_mm);
    });
    std::vector<double> frame_rms;
    for (const RigidAlignment& a : align) {
      if (a.ok) frame_rms.push_back(a.rms_residual);
    }
    if (frame_rms.empty()) return Status::Error("instrument fit: no frame could be aligned");
    const double med = Median(frame_rms);
    const double frame_gate = std::max(
        options.min_point_gate_mm,
        med + options.frame_gate_sigmas * kMadToSigma * MedianAbsDeviation(frame_rms, med));
    std::vector<double> point_residuals;
    summary.frames_in_template = 0;
    for (int f = 0; f < num_frames; ++f) {
      used[f] = align[f].ok && align[f].rms_residual <= frame_gate;
      if (!used[f]) continue;
      ++summary.frames_in_template;
      for (int k : rigid) {
        if (!(align[f].inlier_mask & (1u << k))) continue;
        point_residuals.push_back(
            (pts[f].col(k) - align[f].target_from_source * shape.col(k)).norm());
      }
    }
    Eigen::Matrix3Xd updated =
        UpdateTemplate(pts, align, used, rigid, options.min_observations_per_point);
    // The template's own placement is free (a gauge): the per-coordinate median is not
    // rotation-equivariant, so without this the template creeps a little every pass.
    // Align the update rigidly onto the previous shape before comparing.
    std::vector<int> common;
    for (int k : rigid) {
      if (shape.col(k).allFinite() && updated.col(k).allFinite()) common.push_back(k);
    }
    RigidMatrix3d shape_from_updated;
    if (FitRigidSubset(updated, shape, common, options.min_spread_mm, &shape_from_updated)) {
      updated = (shape_from_updated.rotation * updated).colwise() + shape_from_updated.translation;
    }
    const double change = MaxChange(shape, updated);
    shape = updated;
    gate = std::clamp(options.point_gate_factor * Median(point_residuals),
                      options.min_point_gate_mm,
                      options.max_point_gate_mm);
    if (change < options.convergence_mm) {
      summary.converged = true;
      break;
    }
  }
  const StringEdges edges{shape.col(model.nut_l()),
                          shape.col(model.nut_r()),
                          shape.col(model.bridge_l()),
                          shape.col(model.bridge_r())};
  if (!edges.nut_l.allFinite() || !edges.nut_r.allFinite() || !edges.bridge_l.allFinite() ||
      !edges.bridge_r.allFinite()) {
    return Status::Error(
        "instrument fit: the nut/bridge keypoints were not observed "
        "consistently in enough frames");
  }

  // 4. Front side by majority vote of the hints mapped into the template frame.
  StringGeometryOptions geometry_options = options.strings;
  geometry_options.world_units_per_mm = 1.0;  // template coordinates are mm
  ARCO_ASSIGN_OR_RETURN(
      InstrumentGeometry first,
      GeometryFromEdges(
          model, edges, {FrontHint::Kind::kFrontDirection, {1, 2, 3}}, geometry_options));
  const Eigen::Vector3d z_first = first.world_from_instrument.rotation.col(2);
  const Eigen::Vector3d mid = first.world_from_instrument * Eigen::Vector3d(0.5 * length_mm, 0, 0);
  int votes_for = 0, votes_against = 0;
  std::vector<double> margins;
  const bool direction_hints = hints.front().kind == FrontHint::Kind::kFrontDirection;
  for (int f = 0; f < num_frames; ++f) {
    const FrontHint& h = hints.size() == 1 ? hints.front() : hints[f];
    if (!align[f].ok || !h.value.allFinite()) continue;
    double s = 0;
    if (h.kind == FrontHint::Kind::kFrontDirection) {
      if (!(h.value.norm() > 0)) continue;
      s = z_first.dot(align[f].target_from_source.rotation.transpose() * h.value.normalized());
      margins.push_back(std::asin(std::min(1.0, std::abs(s))) * 180.0 / 3.14159265358979323846);
    } else {
      const Eigen::Vector3d p = align[f].target_from_source.rotation.transpose() *
                                (h.value / u - align[f].target_from_source.translation);
      s = z_first.dot(p - mid);
      if (h.kind == FrontHint::Kind::kPerformerPoint) s = -s;
      margins.push_back(std::abs(s));
    }
    (s >= 0 ? votes_for : votes_against) += 1;
  }
  summary.front_votes = votes_for + votes_against;
  const Eigen::Vector3d front = votes_for >= votes_against ? z_first : Eigen::Vector3d(-z_first);
  summary.front_agreement = summary.front_votes > 0
                                ? std::max(votes_for, votes_against) / double(summary.front_votes)
                                : 0;

  // Final scale over the template frames whose four nut/bridge points are inliers.
  const uint32_t nut_bridge_bits = (1u << model.nut_l()) | (1u << model.nut_r()) |
                                   (1u << model.bridge_l()) | (1u << model.bridge_r());
  std::vector<double> inlier_distances;
  for (int f = 0; f < num_frames; ++f) {
    if (used[f] && (align[f].inlier_mask & nut_bridge_bits) == nut_bridge_bits) {
      inlier_distances.push_back(NutBridge(model, keypoints_in_world[f]));
    }
  }
  if (inlier_distances.empty()) inlier_distances = distances;
  const double final_distance = Median(inlier_distances);
  InstrumentTemplate& instrument = fit.instrument;
  instrument.scale_frames = static_cast<int>(inlier_distances.size());
  instrument.nut_bridge_spread_rel =
      kMadToSigma * MedianAbsDeviation(inlier_distances, final_distance) / final_distance;
  if (options.scale == InstrumentFitOptions::Scale::kFromStringLength) {
    const double u_final = final_distance / length_mm;
    shape *= u / u_final;  // template mm under the refined scale
    u = u_final;
  }
  instrument.world_units_per_mm = u;

  // The instrument frame from the (rescaled) template.
  const StringEdges scaled{shape.col(model.nut_l()),
                           shape.col(model.nut_r()),
                           shape.col(model.bridge_l()),
                           shape.col(model.bridge_r())};
  ARCO_ASSIGN_OR_RETURN(
      InstrumentGeometry geometry,
      GeometryFromEdges(
          model, scaled, {FrontHint::Kind::kFrontDirection, front}, geometry_options));
  instrument.order = geometry.order;
  instrument.order.front_margin_mm = Median(margins);
  const bool margin_small =
      direction_hints ? instrument.order.front_margin_mm < options.strings.min_front_angle_deg
                      : instrument.order.front_margin_mm < options.strings.min_front_margin_mm;
  std::string front_problem;
  if (summary.front_votes == 0) {
    front_problem = "no usable front hint: string order ambiguous";
  } else if (summary.front_agreement < options.min_front_agreement) {
    front_problem = "front hints agree in only " + Percent(summary.front_agreement) +
                    " of frames: string order ambiguous";
  } else if (!std::isfinite(instrument.order.front_margin_mm) || margin_small) {
    front_problem = "front hints lie near the top-plate plane: string order ambiguous";
  }
  if (!front_problem.empty()) {
    instrument.order.ambiguous = true;
    instrument.order.warning = instrument.order.warning.empty()
                                   ? front_problem
                                   : instrument.order.warning + "; " + front_problem;
  }
  instrument.strings_in_instrument = geometry.strings_in_instrument;
  instrument.keypoints_in_instrument.assign(num_keypoints, Eigen::Vector3d::Constant(kNaN));
  for (int k : rigid) {
    if (shape.col(k).allFinite()) {
      instrument.keypoints_in_instrument[k] =
          geometry.world_from_instrument.InverseMap(shape.col(k));
    }
  }

  // 5. Final per-frame poses and the clip-level residual gate.
  const double final_gate = gate;
  summary.point_gate_mm = final_gate;
  fit.frames.resize(num_frames);
  ParallelFor(num_frames, options.num_threads, [&](int64_t f, int) {
    fit.frames[f] =
        FitFramePose(instrument, keypoints_in_world[f], final_gate, options.min_spread_mm);
  });
  std::vector<double> frame_rms;
  for (const InstrumentFramePose& p : fit.frames) {
    if (p.has_pose()) frame_rms.push_back(p.rms_residual_mm);
  }
  summary.median_rms_residual_mm = Median(frame_rms);
  const double frame_gate =
      std::max(options.min_point_gate_mm,
               summary.median_rms_residual_mm +
                   options.frame_gate_sigmas * kMadToSigma *
                       MedianAbsDeviation(frame_rms, summary.median_rms_residual_mm));
  for (InstrumentFramePose& p : fit.frames) {
    if (!p.has_pose()) continue;
    ++summary.frames_with_pose;
    if (p.rms_residual_mm > frame_gate) {
      p.status = FrameFitStatus::kHighResidual;
      ++summary.frames_high_residual;
    }
  }
  if (!instrument.order.warning.empty()) summary.warnings.push_back(instrument.order.warning);
  if (instrument.nut_bridge_spread_rel > 0.05) {
    summary.warnings.push_back("nut-bridge distance varies by " +
                               Percent(instrument.nut_bridge_spread_rel) + " over the clip");
  }
  if (summary.frames_with_pose < num_frames) {
    summary.warnings.push_back(std::to_string(num_frames - summary.frames_with_pose) +
                               " frames have too few keypoints for a pose");
  }
  if (!summary.converged) summary.warnings.push_back("template fit did not converge");
  return fit;
}

}  // namespace arco
