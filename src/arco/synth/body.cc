#include "arco/synth/body.h"

#include <algorithm>
#include <cmath>

#include "arco/synth/random.h"

namespace arco::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// Seated adult, performer frame (mm). The hip joints sit 80 mm above the seat.
const Eigen::Vector3d kHipL(95, 80, 0), kHipR(-95, 80, 0);
const Eigen::Vector3d kShoulderL(180, 540, 10), kShoulderR(-180, 540, 10);
const Eigen::Vector3d kHeadCentre(0, 690, 30);
constexpr double kFloorY = -480;  // seat height 480 mm
constexpr double kUpperArmMm = 290, kForearmMm = 255;

Eigen::Matrix3d RotX(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d RotY(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d RotZ(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// Rotation whose columns are the instrument axes given the string axis x and an
// approximate front direction.
Eigen::Matrix3d FrameFromAxes(const Eigen::Vector3d& x_axis, const Eigen::Vector3d& front) {
  const Eigen::Vector3d x = x_axis.normalized();
  const Eigen::Vector3d z = (front - front.dot(x) * x).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

// 68-point face template (iBUG order) in the head frame: x left, y up, z forward.
std::array<Eigen::Vector3d, wholebody::kNumFace> FaceTemplate() {
  std::array<Eigen::Vector3d, wholebody::kNumFace> f;
  for (int i = 0; i < 17; ++i) {  // jaw, from the subject's right ear to the left
    const double u = kPi * i / 16.0;
    f[i] = {-68 * std::cos(u), -20 - 62 * std::sin(u), 30 + 60 * std::sin(u)};
  }
  for (int i = 0; i < 5; ++i) {  // brows: right 17-21, left 22-26
    f[17 + i] = {-58 + 10.0 * i, 38 + 4 * std::sin(kPi * i / 4), 88};
    f[22 + i] = {18 + 10.0 * i, 38 + 4 * std::sin(kPi * i / 4), 88};
  }
  for (int i = 0; i < 4; ++i) f[27 + i] = {0, 25 - 10.0 * i, 92 + 5.0 * i};  // nose bridge
  for (int i = 0; i < 5; ++i) f[31 + i] = {-14 + 7.0 * i, -14 - 2 * std::sin(kPi * i / 4), 98};
  for (int e = 0; e < 2; ++e) {  // eyes: right 36-41, left 42-47
    const double cx = e == 0 ? -32 : 32;
    for (int i = 0; i < 6; ++i) {
      const double a = kPi - 2 * kPi * i / 6.0;
      f[36 + 6 * e + i] = {cx + 13 * std::cos(a), 20 + 5 * std::sin(a), 84};
    }
  }
  for (int i = 0; i < 12; ++i) {  // outer lip 48-59
    const double a = kPi - 2 * kPi * i / 12.0;
    f[48 + i] = {25 * std::cos(a), -42 + 10 * std::sin(a), 90};
  }
  for (int i = 0; i < 8; ++i) {  // inner lip 60-67
    const double a = kPi - 2 * kPi * i / 8.0;
    f[60 + i] = {15 * std::cos(a), -42 + 3 * std::sin(a), 91};
  }
  return f;
}

}  // namespace

Sway::Sway(const SwayOptions& options, uint64_t seed) {
  Rng rng = Rng::Stream(seed, 202);
  for (int i = 0; i < 6; ++i) {
    const double amp = i < 3 ? options.torso_deg : options.instrument_deg;
    amp_rad_[i] = amp * kDeg * rng.Uniform(0.6, 1.0);
    freq_hz_[i] = rng.Uniform(options.min_hz, options.max_hz);
    phase_rad_[i] = rng.Uniform(0, 2 * kPi);
  }
}

Eigen::Matrix3d Sway::TorsoRotation(double t) const {
  auto a = [&](int i) { return amp_rad_[i] * std::sin(2 * kPi * freq_hz_[i] * t + phase_rad_[i]); };
  return RotY(a(0)) * RotX(a(1)) * RotZ(a(2));
}

Eigen::Matrix3d Sway::InstrumentRotation(double t) const {
  auto a = [&](int i) { return amp_rad_[i] * std::sin(2 * kPi * freq_hz_[i] * t + phase_rad_[i]); };
  return RotY(a(3)) * RotX(a(4)) * RotZ(a(5));
}

RigidMatrix3d InstrumentRestPose(InstrumentKind kind, double scale) {
  RigidMatrix3d pose;
  if (kind == InstrumentKind::kViolin || kind == InstrumentKind::kViola) {
    // Scroll forward-left, slightly up; top plate up, tilted 25 degrees so the
    // high-string side (-y) is lower (towards the player's right front).
    const double yaw = 45 * kDeg, pitch = 8 * kDeg;
    const Eigen::Vector3d x(
        std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
    Eigen::Matrix3d r = FrameFromAxes(x, Eigen::Vector3d::UnitY());
    r = Eigen::AngleAxisd(25 * kDeg, r.col(0)).toRotationMatrix() * r;
    pose.rotation = r;
    pose.translation = Eigen::Vector3d(60, 600, 60) + r.col(0) * (200.0 * scale / 0.4719);
    // 0.4719 = 328 / 695: 200 mm from chin rest to bridge on a full-size violin.
    return pose;
  }
  // Cello / double bass: string axis 55 degrees above horizontal, leaning back
  // towards the performer and 12 degrees to the left; a slight roll.
  const double elevation = 55 * kDeg, yaw = 12 * kDeg;
  const Eigen::Vector3d x(std::sin(yaw) * std::cos(elevation),
                          std::sin(elevation),
                          -std::cos(yaw) * std::cos(elevation));
  Eigen::Matrix3d r = FrameFromAxes(x, Eigen::Vector3d::UnitZ());
  r = Eigen::AngleAxisd(-8 * kDeg, r.col(0)).toRotationMatrix() * r;
  pose.rotation = r;
  // A point on the string axis's side of the body, (-691 s, 0, -120 s), stands on the floor
  // in front: it places the instrument against the synthetic performer, who was built
  // around it. (It was the nominal end pin; the real cello's, nominal_keypoints.h, lies
  // farther behind the strings' plane, where a spike angled towards the player ends.)
  const Eigen::Vector3d end_pin_template(-691 * scale, 0, -120 * scale);
  const double reach = 691 * scale + 695 * scale;  // end pin to nut along the axis
  const Eigen::Vector3d floor_point(-35, kFloorY, reach * std::cos(elevation) * std::cos(yaw) + 40);
  pose.translation = floor_point - r * end_pin_template;
  return pose;
}

Eigen::Vector3d InstrumentPivot(InstrumentKind kind, double scale) {
  const RigidMatrix3d rest = InstrumentRestPose(kind, scale);
  if (kind == InstrumentKind::kViolin || kind == InstrumentKind::kViola) {
    return {60, 600, 60};
  }
  return rest * Eigen::Vector3d(-691 * scale, 0, -120 * scale);
}

Eigen::Vector3d LeftShoulder(const Eigen::Matrix3d& torso) { return torso * kShoulderL; }
Eigen::Vector3d RightShoulder(const Eigen::Matrix3d& torso) { return torso * kShoulderR; }

Eigen::Vector3d ElbowPosition(const Eigen::Vector3d& shoulder,
                              const Eigen::Vector3d& wrist,
                              double a,
                              double b,
                              const Eigen::Vector3d& pole) {
  const Eigen::Vector3d sw = wrist - shoulder;
  const double d_raw = sw.norm();
  if (d_raw < 1e-9) return shoulder + a * pole.normalized();
  const Eigen::Vector3d w = sw / d_raw;
  const double d = std::clamp(d_raw, std::abs(a - b) + 1e-6, a + b - 1e-6);
  const double cos_alpha = std::clamp((a * a + d * d - b * b) / (2 * a * d), -1.0, 1.0);
  Eigen::Vector3d p = pole - pole.dot(w) * w;
  if (p.norm() < 1e-9) p = w.unitOrthogonal();
  p.normalize();
  if (d_raw >= a + b) return shoulder + w * (a * d_raw / (a + b));  // stretched arm
  return shoulder + a * (cos_alpha * w + std::sqrt(1 - cos_alpha * cos_alpha) * p);
}

void BodyKeypoints(const Eigen::Matrix3d& torso,
                   const Eigen::Vector3d& left_wrist,
                   const Eigen::Vector3d& right_wrist,
                   bool violin_hold,
                   std::array<Eigen::Vector3d, wholebody::kNumPoints>* out) {
  auto& p = *out;
  // Head: turned left and tilted onto the chin rest for violin/viola.
  const Eigen::Matrix3d head =
      torso * (violin_hold ? Eigen::Matrix3d(RotY(25 * kDeg) * RotZ(-12 * kDeg) * RotX(10 * kDeg))
                           : Eigen::Matrix3d(RotY(8 * kDeg) * RotX(6 * kDeg)));
  const Eigen::Vector3d head_centre = torso * kHeadCentre;
  static const std::array<Eigen::Vector3d, wholebody::kNumFace> face = FaceTemplate();
  for (int i = 0; i < wholebody::kNumFace; ++i)
    p[wholebody::kFaceFirst + i] = head_centre + head * face[i];
  p[0] = head_centre + head * Eigen::Vector3d(0, 0, 108);    // nose
  p[1] = head_centre + head * Eigen::Vector3d(32, 20, 84);   // left eye
  p[2] = head_centre + head * Eigen::Vector3d(-32, 20, 84);  // right eye
  p[3] = head_centre + head * Eigen::Vector3d(76, 10, 0);    // left ear
  p[4] = head_centre + head * Eigen::Vector3d(-76, 10, 0);   // right ear
  p[5] = torso * kShoulderL;
  p[6] = torso * kShoulderR;
  // Elbows: the left elbow hangs down and out (cello) or under the instrument
  // (violin); the right elbow follows the bow arm, down and out to the right.
  const Eigen::Vector3d left_pole =
      violin_hold ? Eigen::Vector3d(-0.3, -1, 0.2) : Eigen::Vector3d(1, -0.6, 0);
  p[7] = ElbowPosition(p[5], left_wrist, kUpperArmMm, kForearmMm, torso * left_pole);
  p[8] = ElbowPosition(
      p[6], right_wrist, kUpperArmMm, kForearmMm, torso * Eigen::Vector3d(-1, -0.8, 0));
  p[9] = left_wrist;
  p[10] = right_wrist;
  p[11] = kHipL;
  p[12] = kHipR;
  const double knee_x = violin_hold ? 160 : 260;
  p[13] = {knee_x, 60, 430};
  p[14] = {-knee_x, 60, 430};
  p[15] = {knee_x + 30, kFloorY + 80, 470};
  p[16] = {-knee_x - 30, kFloorY + 80, 470};
  // Feet: big toe, small toe, heel (left, then right).
  p[17] = {knee_x + 20, kFloorY + 5, 660};
  p[18] = {knee_x + 70, kFloorY + 5, 630};
  p[19] = {knee_x + 30, kFloorY + 10, 440};
  p[20] = {-knee_x - 20, kFloorY + 5, 660};
  p[21] = {-knee_x - 70, kFloorY + 5, 630};
  p[22] = {-knee_x - 30, kFloorY + 10, 440};
}

}  // namespace arco::synth
