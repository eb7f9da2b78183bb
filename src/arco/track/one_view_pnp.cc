#include "arco/track/one_view_pnp.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace arco::track {

std::optional<OneViewPnp> EpnpInRansac(const std::vector<Eigen::Vector3d>& object_points,
                                       const std::vector<Eigen::Vector2d>& pixels,
                                       const Eigen::Matrix3d& K,
                                       double gate_px,
                                       int min_inliers) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (const Eigen::Vector3d& p : object_points) object.emplace_back(p.x(), p.y(), p.z());
  for (const Eigen::Vector2d& p : pixels) image.emplace_back(p.x(), p.y());
  const cv::Matx33d k(
      K(0, 0), K(0, 1), K(0, 2), K(1, 0), K(1, 1), K(1, 2), K(2, 0), K(2, 1), K(2, 2));
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  if (!cv::solvePnPRansac(object,
                          image,
                          k,
                          cv::noArray(),
                          rvec,
                          tvec,
                          false,
                          100,
                          static_cast<float>(gate_px),
                          0.999,
                          inliers,
                          cv::SOLVEPNP_EPNP) ||
      static_cast<int>(inliers.size()) < min_inliers)
    return std::nullopt;
  OneViewPnp out;
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  for (int r = 0; r < 3; ++r) {
    out.angle_axis[r] = rvec.at<double>(r);
    out.translation[r] = tvec.at<double>(r);
    for (int c = 0; c < 3; ++c) out.cam_from_object.rotation(r, c) = R(r, c);
  }
  out.cam_from_object.translation = out.translation;
  out.inliers = std::move(inliers);
  return out;
}

}  // namespace arco::track
