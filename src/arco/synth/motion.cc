#include "arco/synth/motion.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "arco/audio/audio_reader.h"
#include "arco/geometry/alignment.h"
#include "arco/hand/hand_model.h"
#include "arco/registry/instruments.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/body.h"
#include "arco/synth/error_model.h"
#include "arco/synth/synth_instrument.h"
#include "arco/util/stats.h"

namespace arco::synth {
namespace {

constexpr int kContactExtras = 13;  // 4 strings x 2 ends, contact, playing MCP..tip
// The annotation's playing finger is a copy of one left-hand finger (SPD's contact stage):
// the tips coincide to rounding. Farther than this, the frame's finger is unknown.
constexpr double kSameTipMm = 1.0;

double DistanceToSegment(const Eigen::Vector3d& p,
                         const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

RigidMatrix3d ToRigid(const Sim3d& s) { return {s.RotationMatrix(), s.translation}; }

bool SeesAll(const Camera& cam, const std::vector<Eigen::Vector3d>& points) {
  for (const Eigen::Vector3d& x : points) {
    const auto px = cam.Project(x);
    if (!px || px->x() < 0 || px->y() < 0 || px->x() >= cam.width || px->y() >= cam.height)
      return false;
  }
  return true;
}

// MotionOptions::cameras applied to the rig (mm) that sees `points`.
StatusOr<Rig> SelectCameras(const Rig& rig,
                            const std::string& spec,
                            const std::vector<Eigen::Vector3d>& points) {
  if (spec.empty()) return rig;
  Rig out = rig;
  out.cameras.clear();
  const bool count = spec.find_first_not_of("0123456789") == std::string::npos;
  if (!count) {
    size_t start = 0;
    while (start <= spec.size()) {
      const size_t end = std::min(spec.find(',', start), spec.size());
      const std::string name = spec.substr(start, end - start);
      bool found = false;
      for (const Camera& c : rig.cameras) {
        if (c.name == name || (!c.serial.empty() && c.serial == name)) {
          out.cameras.push_back(c);
          found = true;
        }
      }
      if (!found) return Status::Error("cameras: no camera '" + name + "' in the rig");
      start = end + 1;
    }
    return out;
  }
  const int n = std::atoi(spec.c_str());
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : points) centre += x;
  centre /= static_cast<double>(points.size());
  std::vector<int> seeing;
  std::vector<Eigen::Vector3d> direction;  // performer -> camera, unit
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    if (!SeesAll(rig.cameras[i], points)) continue;
    seeing.push_back(static_cast<int>(i));
    direction.push_back((rig.cameras[i].CenterInWorld() - centre).normalized());
  }
  if (n < 1 || n > static_cast<int>(seeing.size())) {
    return Status::Error("cameras: " + spec + " requested, " + std::to_string(seeing.size()) +
                         " cameras see the instrument");
  }
  // Start from the camera nearest the mean viewing direction, then farthest-point.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& d : direction) mean += d;
  std::vector<int> chosen;
  int first = 0;
  for (size_t k = 1; k < direction.size(); ++k)
    if (direction[k].dot(mean) > direction[static_cast<size_t>(first)].dot(mean))
      first = static_cast<int>(k);
  chosen.push_back(first);
  while (static_cast<int>(chosen.size()) < n) {
    int best = -1;
    double best_angle = -1;
    for (size_t k = 0; k < direction.size(); ++k) {
      double nearest = INFINITY;
      for (int c : chosen)
        nearest = std::min(
            nearest,
            std::acos(std::clamp(direction[k].dot(direction[static_cast<size_t>(c)]), -1.0, 1.0)));
      if (nearest > best_angle) best_angle = nearest, best = static_cast<int>(k);
    }
    chosen.push_back(best);
  }
  std::sort(chosen.begin(), chosen.end());
  for (int c : chosen)
    out.cameras.push_back(rig.cameras[static_cast<size_t>(seeing[static_cast<size_t>(c)])]);
  return out;
}

}  // namespace

Status MotionOptions::Validate() const {
  if (motion_path.empty()) return Status::Error("motion: no motion file");
  if (audio_path.empty()) return Status::Error("motion: no audio file (--audio)");
  if (!(fps >= 1 && fps <= 1000)) return Status::Error("fps must be in [1, 1000]");
  if (!(max_duration_s >= 0) || !std::isfinite(max_duration_s))
    return Status::Error("max_duration_s must be >= 0 s (0 = whole take)");
  if (num_threads < 0) return Status::Error("threads must be >= 0");
  ARCO_RETURN_IF_ERROR(ErrorModelOptions(error_model).status());
  ARCO_RETURN_IF_ERROR(stage.Validate());
  return detection.Validate();
}

StatusOr<SyntheticCapture> GenerateFromMotion(const Rig& rig, const MotionOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const std::string& path = options.motion_path;
  SyntheticCapture cap;
  cap.options.instrument = options.instrument;
  cap.options.fps = options.fps;
  cap.options.a4_hz = options.a4_hz;
  cap.options.seed = options.seed;
  cap.options.num_threads = options.num_threads;
  cap.options.stage = options.stage;
  cap.options.detection = options.detection;
  cap.options.piece = "recorded";
  cap.motion_source = path;
  cap.audio_source = options.audio_path;
  cap.error_model = ErrorModelJson(options.error_model, options.detection);

  ARCO_ASSIGN_OR_RETURN(const InstrumentKind kind, ParseInstrumentKind(options.instrument));
  InstrumentOptions io;
  io.kind = kind;
  io.tuning.a4_hz = options.a4_hz;
  ARCO_ASSIGN_OR_RETURN(const InstrumentModel model, InstrumentModel::Create(io));
  cap.instrument_kind = kind;
  ARCO_ASSIGN_OR_RETURN(const InstrumentTemplate tmpl, MakeInstrumentTemplate(model));
  cap.layout = GetInstrumentInfo(kind).spd_layout;
  cap.truth_layout = cap.layout + "_contact";
  const KeypointLayout* layout = FindKeypointLayout(cap.layout);
  if (layout == nullptr) return Status::Error("internal: no layout " + cap.layout);
  cap.keypoint_names = layout->names;
  cap.num_instrument_points = static_cast<int>(model.keypoint_names().size());
  const int num_capture = wholebody::kNumPoints + cap.num_instrument_points;
  const int num_truth = num_capture + kContactExtras;
  if (layout->size() != num_capture)
    return Status::Error("internal: layout " + cap.layout + " does not match the instrument");

  // The recorded array.
  ARCO_ASSIGN_OR_RETURN(const NpyHeader header, ReadNpyHeader(path));
  if (header.shape.size() != 3 || header.shape[1] != num_truth || header.shape[2] != 3) {
    std::string shape;
    for (int64_t d : header.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    return Status::Error(path + ": shape (" + shape + ") is not (frames, " +
                         std::to_string(num_truth) + ", 3), the " + cap.truth_layout +
                         " layout of a " + options.instrument);
  }
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> recorded, ReadNpy<double>(path));
  int frames = static_cast<int>(recorded.shape[0]);
  if (options.max_duration_s > 0)
    frames = std::min(frames, static_cast<int>(std::floor(options.max_duration_s * options.fps)));
  if (frames < 2) return Status::Error(path + ": fewer than 2 frames");
  // Every point but the contact extras is finite; the contact point and the playing finger
  // are all finite (pressed) or all NaN (open string or rest).
  for (int f = 0; f < frames; ++f) {
    for (int p = 0; p < num_capture + 8; ++p) {
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(recorded.at(f, p, c))) {
          const std::string name = p < num_capture
                                       ? layout->names[static_cast<size_t>(p)]
                                       : "string end " + std::to_string(p - num_capture);
          return Status::Error(path + ": frame " + std::to_string(f) + ": point " +
                               std::to_string(p) + " (" + name +
                               ") is not finite (only the contact point and the playing finger "
                               "may be NaN)");
        }
      }
    }
    int finite = 0;
    for (int p = num_capture + 8; p < num_truth; ++p)
      finite += std::isfinite(recorded.at(f, p, 0)) && std::isfinite(recorded.at(f, p, 1)) &&
                std::isfinite(recorded.at(f, p, 2));
    if (finite != 0 && finite != 5) {
      return Status::Error(path + ": frame " + std::to_string(f) +
                           ": the contact point and the playing finger's 4 joints must be all "
                           "finite or all NaN (" +
                           std::to_string(finite) + " of 5 finite)");
    }
  }

  // The audio covers the motion (frame f at f / fps).
  {
    ARCO_ASSIGN_OR_RETURN(auto reader, audio::OpenAudio(options.audio_path));
    const audio::AudioInfo& info = reader->info();
    int64_t samples = info.frames;
    if (samples < 0) {  // a container that does not say: count
      std::vector<float> buffer(1 << 16);
      samples = 0;
      while (true) {
        ARCO_ASSIGN_OR_RETURN(const int64_t n,
                              reader->ReadMono(buffer.data(), static_cast<int64_t>(buffer.size())));
        if (n == 0) break;
        samples += n;
      }
    }
    samples -= info.missing_frames;
    const double audio_s = static_cast<double>(samples) / info.sample_rate_hz;
    const double motion_s = (frames - 1) / options.fps;
    if (audio_s < motion_s) {
      char msg[256];
      std::snprintf(msg,
                    sizeof(msg),
                    ": %.2f s of audio is shorter than the motion (%d frames at %g fps: %.2f s)",
                    audio_s,
                    frames,
                    options.fps,
                    motion_s);
      return Status::Error(options.audio_path + msg);
    }
  }

  // The stage, and one rigid transform for the take: the recorded instrument's median
  // keypoints onto the template at its rest pose on the stage.
  ARCO_ASSIGN_OR_RETURN(cap.stage, PlaceStage(rig, options.stage));
  cap.rig_mm = ScaleRigToMm(rig, cap.stage.mm_per_unit);
  const RigidMatrix3d& world_from_performer = cap.stage.world_from_performer;
  const RigidMatrix3d world_from_rest = world_from_performer * InstrumentRestPose(kind, tmpl.scale);
  std::vector<int> rigid_points;  // instrument keypoints of the template (not frog, tip)
  for (int i = 0; i < cap.num_instrument_points; ++i)
    if (tmpl.keypoints_mm[static_cast<size_t>(i)].allFinite()) rigid_points.push_back(i);
  std::vector<Eigen::Vector3d> source, target;
  for (int i : rigid_points) {
    Eigen::Vector3d median;
    for (int c = 0; c < 3; ++c) {
      std::vector<double> v(static_cast<size_t>(frames));
      for (int f = 0; f < frames; ++f)
        v[static_cast<size_t>(f)] = recorded.at(f, wholebody::kNumPoints + i, c);
      median[c] = Median(v);
    }
    source.push_back(median);
    target.push_back(world_from_rest * tmpl.keypoints_mm[static_cast<size_t>(i)]);
  }
  const auto placed = AlignPoints(source, target, {}, AlignmentOptions{});
  if (!placed) {
    return Status::Error(path + ": the instrument's keypoints are degenerate (cannot place it)");
  }
  const RigidMatrix3d world_from_recorded = ToRigid(placed->target_from_source);

  // The moved take.
  cap.num_frames = frames;
  cap.points3d.shape = {frames, num_truth, 3};
  cap.points3d.data.assign(static_cast<size_t>(cap.points3d.size()), NAN);
  for (int f = 0; f < frames; ++f) {
    for (int p = 0; p < num_truth; ++p) {
      const Eigen::Vector3d x(recorded.at(f, p, 0), recorded.at(f, p, 1), recorded.at(f, p, 2));
      if (!x.allFinite()) continue;
      const Eigen::Vector3d y = world_from_recorded * x;
      for (int c = 0; c < 3; ++c) cap.points3d.at(f, p, c) = y[c];
    }
  }
  auto point = [&](int f, int p) {
    return Eigen::Vector3d(
        cap.points3d.at(f, p, 0), cap.points3d.at(f, p, 1), cap.points3d.at(f, p, 2));
  };

  // The cameras that film the take; the rig must see the performer: the instrument in at
  // least two cameras (one camera: in that one).
  ARCO_ASSIGN_OR_RETURN(cap.rig_mm, SelectCameras(cap.rig_mm, options.cameras, target));
  {
    int seeing = 0;
    for (const Camera& cam : cap.rig_mm.cameras) seeing += SeesAll(cam, target);
    const int needed = std::min<int>(2, static_cast<int>(cap.rig_mm.cameras.size()));
    if (seeing < needed || seeing == 0) {
      return Status::Error("the rig sees the placed instrument in " + std::to_string(seeing) +
                           " camera(s); at least " + std::to_string(std::max(needed, 1)) +
                           " must see it");
    }
  }

  const int n_strings = model.num_strings();
  cap.contact.resize(static_cast<size_t>(frames));
  cap.world_from_instrument.resize(static_cast<size_t>(frames));
  std::vector<DetectionFrame> det(static_cast<size_t>(frames));
  const int frog = wholebody::kNumPoints + model.KeypointIndex("frog");
  const int tip = wholebody::kNumPoints + model.KeypointIndex("tip");
  for (int f = 0; f < frames; ++f) {
    // Instrument pose: the template fitted to this frame's instrument keypoints.
    std::vector<Eigen::Vector3d> tmpl_points, frame_points;
    for (int i : rigid_points) {
      tmpl_points.push_back(tmpl.keypoints_mm[static_cast<size_t>(i)]);
      frame_points.push_back(point(f, wholebody::kNumPoints + i));
    }
    const auto fitted = AlignPoints(tmpl_points, frame_points, {}, AlignmentOptions{});
    if (!fitted) {
      return Status::Error(path + ": frame " + std::to_string(f) +
                           ": the instrument's keypoints are degenerate");
    }
    const RigidMatrix3d world_from_instrument = ToRigid(fitted->target_from_source);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = world_from_instrument.rotation;
    m.topRightCorner<3, 1>() = world_from_instrument.translation;
    cap.world_from_instrument[static_cast<size_t>(f)] = m;

    // Contact: the nearest string to the contact point; the finger whose tip the
    // annotation's playing tip is.
    ContactTruth& ct = cap.contact[static_cast<size_t>(f)];
    DetectionFrame& df = det[static_cast<size_t>(f)];
    const Eigen::Vector3d contact = point(f, num_capture + 8);
    if (contact.allFinite()) {
      int best_string = -1;
      double best = INFINITY;
      for (int k = 0; k < n_strings; ++k) {  // k = 0 is the lowest string
        const double d = DistanceToSegment(
            contact, point(f, num_capture + 2 * k), point(f, num_capture + 2 * k + 1));
        if (d < best) best = d, best_string = k;
      }
      const Eigen::Vector3d playing_tip = point(f, num_capture + 12);
      int finger = 0;
      for (int g = 1; g <= 4; ++g) {
        const int t = wholebody::kLeftHandFirst + hand::TipKeypoint(static_cast<hand::Finger>(g));
        if ((point(f, t) - playing_tip).norm() <= kSameTipMm) finger = g;
      }
      if (finger == 0) {
        return Status::Error(path + ": frame " + std::to_string(f) +
                             ": the playing finger's tip is none of the left hand's fingertips");
      }
      ct.string = n_strings - best_string;  // 1 = highest
      ct.finger = finger;
      ct.point_mm = contact;
      ++cap.pressed_frames;
      df.bias_tip =
          wholebody::kLeftHandFirst + hand::TipKeypoint(static_cast<hand::Finger>(finger));
      df.bias_dip = df.bias_tip - 1;
      df.bias_direction = world_from_instrument.rotation.col(2);
    }

    // Detection scene.
    df.points.resize(static_cast<size_t>(num_capture));
    for (int p = 0; p < num_capture; ++p) df.points[static_cast<size_t>(p)] = point(f, p);
    df.body_centre =
        world_from_instrument * Eigen::Vector3d(tmpl.body_center_x_mm, 0, tmpl.body_plane_z_mm);
    df.body_axis_x = world_from_instrument.rotation.col(0);
    df.body_axis_y = world_from_instrument.rotation.col(1);
    df.body_half_x = tmpl.body_half_length_mm;
    df.body_half_y = tmpl.body_half_width_mm;
    df.torso_a = 0.5 * (point(f, 11) + point(f, 12));  // hips
    df.torso_b = 0.5 * (point(f, 5) + point(f, 6));    // shoulders
    // The back of the left hand faces away from the strings: from the string plane's
    // nearest point under the hand's MCP centre to that centre.
    Eigen::Vector3d mcp = Eigen::Vector3d::Zero();
    for (int g = 1; g <= 4; ++g)
      mcp += point(
          f, wholebody::kLeftHandFirst + hand::KeypointIndex(static_cast<hand::Finger>(g), 0));
    mcp /= 4;
    const Eigen::Vector3d mid_nut =
        0.5 * (point(f, num_capture) + point(f, num_capture + 2 * n_strings - 2));
    const Eigen::Vector3d mid_bridge =
        0.5 * (point(f, num_capture + 1) + point(f, num_capture + 2 * n_strings - 1));
    const Eigen::Vector3d axis = (mid_bridge - mid_nut).normalized();
    const Eigen::Vector3d on_neck = mid_nut + (mcp - mid_nut).dot(axis) * axis;
    const Eigen::Vector3d back = mcp - on_neck;
    if (back.norm() > 1) df.left_hand_back = back.normalized();
  }

  DetectionLayout dl;
  dl.num_points = num_capture;
  dl.instrument_first = wholebody::kNumPoints;
  dl.bow_points = {frog, tip};
  dl.torso_points = {5, 6, 11, 12};
  cap.keypoints2d = EmulateDetections(
      cap.rig_mm, det, dl, options.detection, options.fps, options.seed, options.num_threads);
  return cap;
}

}  // namespace arco::synth
