#include "arco/mocap/triangulate_sequence.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "arco/util/parallel.h"
#include "arco/util/stats.h"

namespace arco {

Status SequenceTriangulationOptions::Validate() const {
  if (num_threads < 0) return Status::Error("triangulation options: num_threads must be >= 0");
  return point.Validate();
}

StatusOr<SequenceTriangulation> TriangulateSequence(const Rig& rig,
                                                    const std::vector<int>& view_to_camera,
                                                    const NpyArray<double>& keypoints2d,
                                                    const SequenceTriangulationOptions& options,
                                                    Progress* progress,
                                                    const std::string& source) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const auto& shape = keypoints2d.shape;
  if (shape.size() != 4 || shape[3] != 3) {
    return Status::Error(source + ": 2D keypoints must have shape (frames, views, points, 3)");
  }
  const int64_t num_frames = shape[0], num_views = shape[1], num_points = shape[2];
  if (static_cast<int64_t>(keypoints2d.data.size()) != num_frames * num_views * num_points * 3) {
    return Status::Error(source + ": 2D keypoint data do not match the array's shape");
  }
  if (static_cast<int64_t>(view_to_camera.size()) != num_views) {
    return Status::Error(source + ": " + std::to_string(num_views) + " views in the array but " +
                         std::to_string(view_to_camera.size()) + " cameras listed");
  }
  for (size_t v = 0; v < view_to_camera.size(); ++v) {
    const int c = view_to_camera[v];
    if (c < 0 || c >= static_cast<int>(rig.cameras.size())) {
      return Status::Error(source + ": view " + std::to_string(v) + " has no camera in the rig");
    }
    for (size_t u = 0; u < v; ++u) {
      if (view_to_camera[u] == c) {
        return Status::Error(source + ": views " + std::to_string(u) + " and " + std::to_string(v) +
                             " use the same camera " + rig.cameras[c].name);
      }
    }
  }
  const Triangulator triangulator(rig, options.point);

  SequenceTriangulation out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.points3d.shape = {num_frames, num_points, 3};
  out.points3d.data.assign(static_cast<size_t>(num_frames * num_points * 3), nan);
  out.rms_reprojection_px.shape = {num_frames, num_points};
  out.rms_reprojection_px.data.assign(static_cast<size_t>(num_frames * num_points),
                                      std::numeric_limits<float>::quiet_NaN());
  out.num_inliers.shape = {num_frames, num_points};
  out.num_inliers.data.assign(static_cast<size_t>(num_frames * num_points), 0);
  out.num_views.shape = {num_frames, num_points};
  out.num_views.data.assign(static_cast<size_t>(num_frames * num_points), 0);
  out.inlier_mask.shape = {num_frames, num_points, num_views};
  out.inlier_mask.data.assign(static_cast<size_t>(num_frames * num_points * num_views), 0);

  const int threads = ResolveThreadCount(options.num_threads);
  std::vector<TriangulationScratch> scratch(static_cast<size_t>(threads));
  std::vector<std::vector<PointObservation>> observations(static_cast<size_t>(threads));
  std::vector<int> camera_to_view(rig.cameras.size(), -1);
  for (size_t v = 0; v < view_to_camera.size(); ++v) camera_to_view[view_to_camera[v]] = v;

  ParallelFor(
      num_frames,
      threads,
      [&](int64_t f, int t) {
        auto& obs = observations[t];
        for (int64_t p = 0; p < num_points; ++p) {
          obs.clear();
          int usable = 0;
          for (int64_t v = 0; v < num_views; ++v) {
            // keypoints2d.at(f, v, p, k) without the out-of-line call per value.
            const double* kp =
                &keypoints2d.data[static_cast<size_t>(((f * num_views + v) * num_points + p) * 3)];
            const double x = kp[0], y = kp[1], score = kp[2];
            if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(score)) continue;
            obs.push_back({view_to_camera[v], Eigen::Vector2d(x, y), score});
            usable += score >= options.point.min_score;
          }
          const size_t fp = static_cast<size_t>(f * num_points + p);
          out.num_views.data[fp] = usable;
          const auto result = triangulator.Triangulate(obs, &scratch[t]);
          if (!result) continue;
          for (int k = 0; k < 3; ++k) out.points3d.data[fp * 3 + k] = result->point_in_world[k];
          out.rms_reprojection_px.data[fp] = static_cast<float>(result->rms_reprojection_px);
          out.num_inliers.data[fp] = static_cast<int32_t>(result->inlier_cameras.size());
          for (int c : result->inlier_cameras) {
            out.inlier_mask.data[fp * num_views + camera_to_view[c]] = 1;
          }
        }
        if (progress) progress->Advance(1);
      },
      /*chunk=*/1);
  return out;
}

SequenceTriangulationSummary Summarize(const SequenceTriangulation& result) {
  SequenceTriangulationSummary s;
  s.frames = result.points3d.shape.empty() ? 0 : result.points3d.shape[0];
  s.points = static_cast<int64_t>(result.rms_reprojection_px.data.size());
  std::vector<float> rms;
  int64_t inliers = 0;
  for (size_t i = 0; i < result.rms_reprojection_px.data.size(); ++i) {
    const float r = result.rms_reprojection_px.data[i];
    if (!std::isfinite(r)) continue;
    rms.push_back(r);
    inliers += result.num_inliers.data[i];
  }
  s.triangulated = static_cast<int64_t>(rms.size());
  if (rms.empty()) {
    s.median_rms_reprojection_px = std::numeric_limits<double>::quiet_NaN();
  } else {
    s.median_rms_reprojection_px = MedianInPlace(rms.begin(), rms.end());
    s.mean_inliers = static_cast<double>(inliers) / static_cast<double>(rms.size());
  }
  s.one_view = !result.depth_source.data.empty();
  std::vector<float> sigma;
  for (float x : result.depth_sigma_mm.data)
    if (std::isfinite(x)) sigma.push_back(x);
  if (!sigma.empty()) s.median_depth_sigma_mm = MedianInPlace(sigma.begin(), sigma.end());
  return s;
}

Json ToJson(const SequenceTriangulationSummary& s) {
  Json j = {{"frames", s.frames},
            {"points", s.points},
            {"triangulated", s.triangulated},
            {"median_rms_reprojection_px", JsonFromDouble(s.median_rms_reprojection_px)},
            {"mean_inliers", s.mean_inliers}};
  if (s.one_view) j["median_depth_sigma_mm"] = JsonFromDouble(s.median_depth_sigma_mm);
  return j;
}

}  // namespace arco
