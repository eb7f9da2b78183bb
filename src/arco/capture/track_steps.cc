#include "arco/capture/track_steps.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <utility>

#include "arco/calibration/calibration_file.h"
#include "arco/instrument/instrument_model.h"
#include "arco/instrument/nominal_keypoints.h"
#include "arco/media/video_reader.h"
#include "arco/mocap/labelme.h"
#include "arco/track/bow_tracker.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/util/parallel.h"

namespace arco::capture {
namespace {

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string FormatNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", v);
  return text;
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Each camera's video (gray), read in order or by seeking; frames turned by rotate_deg.
class Frames {
 public:
  Frames(const CaptureManifest& manifest, const std::vector<CaptureVideo>& inputs)
      : images_(inputs.size()) {
    media::VideoReaderOptions gray;
    gray.format = media::PixelFormat::kGray8;
    for (size_t v = 0; v < inputs.size(); ++v) {
      readers_.emplace_back(manifest, static_cast<int>(v), inputs[v], gray);
    }
  }

  // Reads each view's own global frame `camera_frames[v]` (CameraFrameNear; in parallel
  // over views); a null pointer for a view without one (-1) or that dropped it.
  StatusOr<std::vector<const media::Image*>> Read(const std::vector<int64_t>& camera_frames,
                                                  int threads,
                                                  double* decode_s) {
    const auto start = std::chrono::steady_clock::now();
    const int n = static_cast<int>(readers_.size());
    std::vector<Status> status(n, Status::Ok());
    std::vector<const media::Image*> out(n, nullptr);
    ParallelFor(
        n,
        threads,
        [&](int64_t v, int) {
          if (camera_frames[v] < 0) return;
          StatusOr<bool> read = readers_[v].Read(camera_frames[v], &images_[v]);
          if (!read.ok()) {
            status[v] = read.status();
          } else if (*read) {
            out[v] = &images_[v];
          }
        },
        1);
    for (const Status& s : status) ARCO_RETURN_IF_ERROR(s);
    *decode_s += SecondsSince(start);
    return out;
  }

 private:
  std::vector<CaptureFrameReader> readers_;
  std::vector<media::Image> images_;
};

Json ViewJson(const track::ViewTrackReport& r) {
  return Json{{"tracked", r.tracked},
              {"inliers", r.inliers},
              {"residual_px", r.residual_px},
              {"rematched", r.rematched},
              {"added", r.added},
              {"lost", r.lost},
              {"reacquired", r.reacquired}};
}

// Millimetres per world unit of the calibration: its unit when it has one ("mm", "m"),
// else (Metashape's arbitrary chunk units, "unknown") the instrument's labelled nut and
// bridge, whose midpoints lie the model's string length apart, as the instrument stage
// scales the world (instrument/template_fit.h, Scale::kFromStringLength).
StatusOr<double> MmPerWorldUnit(const std::string& units,
                                const std::string& calibration_path,
                                const std::string& instrument,
                                const std::vector<std::string>& names,
                                const std::vector<Eigen::Vector3d>& points,
                                const std::string& label_files) {
  if (units == "mm") return 1.0;
  if (units == "m") return 1000.0;
  const auto point = [&](const char* name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? Eigen::Vector3d::Constant(kNaN) : points[it - names.begin()];
  };
  const Eigen::Vector3d nut = 0.5 * (point("nut_l") + point("nut_r"));
  const Eigen::Vector3d bridge = 0.5 * (point("bridge_l") + point("bridge_r"));
  if (!nut.allFinite() || !bridge.allFinite() || !((nut - bridge).norm() > 0)) {
    return Status::Error(label_files + ": the calibration " + calibration_path + " is in units '" +
                         units +
                         "' (no metric scale): label nut_l, nut_r, bridge_l and bridge_r in two "
                         "views, whose distance gives the scale");
  }
  ARCO_ASSIGN_OR_RETURN(const InstrumentModel model, InstrumentModel::Create(instrument));
  return model.string_length_mm() / (nut - bridge).norm();
}

// Each view's own global frame whose picture is nearest the capture's frame g
// (cameras[].offset_s, drift_ppm: round(CameraFrameAt)), -1 when that is outside the
// capture's rows (before the camera started, after the shortest recording ended). g
// itself for a camera on the capture's clock.
std::vector<int64_t> CameraFramesNear(const TrackCapture& capture, int64_t g) {
  const CaptureManifest& manifest = capture.manifest;
  std::vector<int64_t> out(capture.views(), g);
  for (int v = 0; v < capture.views(); ++v) {
    if (manifest.cameras[v].OnCaptureClock()) continue;
    const int64_t own = std::llround(manifest.CameraFrameAt(v, static_cast<double>(g)));
    out[v] = own >= capture.first && own <= capture.last ? own : -1;
  }
  return out;
}

// The index of point p of view v in frame f (from the first) of keypoints2d.npy.
size_t KeypointIndex(const TrackCapture& capture, int64_t f, int v, int64_t p) {
  const int64_t views = capture.views(), points = capture.layout->size();
  return static_cast<size_t>(((f * views + v) * points + p) * 3);
}

}  // namespace

StatusOr<TrackCapture> OpenTrackCapture(const std::string& capture_dir) {
  TrackCapture c;
  c.dir = capture_dir;
  c.manifest_path = CaptureManifestPath(capture_dir);
  ARCO_ASSIGN_OR_RETURN(c.manifest, ReadCaptureManifest(capture_dir));
  const CaptureManifest& manifest = c.manifest;
  if (manifest.instrument == "none") {
    return Status::Error(c.manifest_path + ": instrument is \"none\": nothing to track");
  }
  ARCO_ASSIGN_OR_RETURN(c.layout_name, DetectionLayoutName(manifest.instrument));
  c.layout = FindKeypointLayout(c.layout_name);
  if (c.layout == nullptr) return Status::Error(c.manifest_path + ": no layout " + c.layout_name);
  c.instrument_slots = c.layout->Group("instrument");
  c.bow_slots = c.layout->Group("bow");
  if (c.instrument_slots == nullptr || c.instrument_slots->empty()) {
    return Status::Error(c.manifest_path + ": layout " + c.layout_name +
                         " has no instrument points");
  }
  if (manifest.frame_count <= 0) return Status::Error(c.manifest_path + ": frames.count is 0");
  c.first = manifest.frame_first;
  c.last = manifest.frame_first + manifest.frame_count - 1;
  ARCO_ASSIGN_OR_RETURN(c.inputs, OpenCaptureVideos(capture_dir, manifest, c.first, c.last));
  c.cameras.resize(c.inputs.size());
  for (size_t v = 0; v < c.inputs.size(); ++v) c.cameras[v] = c.inputs[v].calibration;
  return c;
}

StatusOr<TrackLabels> ReadTrackLabels(const TrackStageOptions& options,
                                      const TrackCapture& capture,
                                      std::vector<std::string>* warnings) {
  const CaptureManifest& manifest = capture.manifest;
  const KeypointLayout& layout = *capture.layout;
  const int views = capture.views();
  const int64_t first = capture.first, last = capture.last;
  TrackLabels labels;
  std::vector<std::string>& names = labels.names;
  std::vector<std::string>& bow_names = labels.bow_names;
  for (int slot : *capture.instrument_slots) names.push_back(layout.names[slot]);
  if (capture.bow_slots != nullptr)
    for (int slot : *capture.bow_slots) bow_names.push_back(layout.names[slot]);
  const int64_t default_frame = options.labels_frame >= 0 ? options.labels_frame : first;
  if (default_frame < first || default_frame > last) {
    return Status::Error("labels_frame " + std::to_string(default_frame) +
                         " is outside the capture's frames " + std::to_string(first) + ":" +
                         std::to_string(last) + " (" + capture.manifest_path + ")");
  }
  std::set<std::string> unknown;
  for (const TrackLabelsFile& file : options.labels) {
    const int v = manifest.FindCamera(file.camera);
    if (v < 0) {
      return Status::Error(file.path + ": camera " + file.camera + " is not in " +
                           capture.manifest_path);
    }
    const int64_t frame = file.frame >= 0 ? file.frame : default_frame;
    if (frame < first || frame > last) {
      return Status::Error(file.path + ": labelled frame " + std::to_string(frame) +
                           " is outside the capture's frames " + std::to_string(first) + ":" +
                           std::to_string(last));
    }
    // The labelled frame is the capture's: the labels of a camera off the capture's
    // clock are of its own frame nearest that moment (docs/track.md, "How to label").
    const int64_t own = CameraFramesNear(capture, frame)[v];
    if (own < 0) {
      return Status::Error(
          file.path + ": camera " + file.camera + " did not record frame " + std::to_string(frame) +
          " of the capture (its offset_s " + FormatNumber(manifest.cameras[v].offset_s) +
          " s puts it at its frame " +
          std::to_string(std::llround(manifest.CameraFrameAt(v, static_cast<double>(frame)))) +
          ", outside " + std::to_string(first) + ":" + std::to_string(last) + ")");
    }
    if (manifest.VideoFrameNumber(v, own) < 0) {
      return Status::Error(file.path + ": camera " + file.camera + " dropped frame " +
                           std::to_string(own));
    }
    ARCO_ASSIGN_OR_RETURN(const LabelmeAnnotation a, ReadLabelme(file.path));
    const Camera& cam = capture.cameras[v];
    if ((a.image_width > 0 && a.image_width != cam.width) ||
        (a.image_height > 0 && a.image_height != cam.height)) {
      return Status::Error(file.path + ": image is " + std::to_string(a.image_width) + "x" +
                           std::to_string(a.image_height) + ", camera " + cam.name + " is " +
                           std::to_string(cam.width) + "x" + std::to_string(cam.height) +
                           " (label the frame as turned by rotate_deg)");
    }
    auto& frame_labels = labels.labelled[frame];
    if (frame_labels.empty()) {
      frame_labels.assign(
          views, std::vector<Eigen::Vector2d>(names.size(), Eigen::Vector2d::Constant(kNaN)));
    }
    auto& bow_frame_labels = labels.bow_labelled[frame];
    if (bow_frame_labels.empty()) {
      bow_frame_labels.assign(
          views, std::vector<Eigen::Vector2d>(bow_names.size(), Eigen::Vector2d::Constant(kNaN)));
    }
    int matched = 0;
    for (const LabeledPoint& p : a.points) {
      const std::string name = CanonicalKeypointName(p.label);
      const auto it = std::find(names.begin(), names.end(), name);
      const auto bow_it = std::find(bow_names.begin(), bow_names.end(), name);
      if (it == names.end() && bow_it == bow_names.end()) {
        unknown.insert(p.label);
        continue;
      }
      if (!(p.pixel.x() >= -0.5 && p.pixel.y() >= -0.5 && p.pixel.x() < cam.width - 0.5 &&
            p.pixel.y() < cam.height - 0.5)) {
        return Status::Error(file.path + ": label " + p.label + " at (" +
                             std::to_string(p.pixel.x()) + ", " + std::to_string(p.pixel.y()) +
                             ") is outside the " + std::to_string(cam.width) + "x" +
                             std::to_string(cam.height) + " image of camera " + cam.name);
      }
      auto& slot = it != names.end() ? frame_labels[v][it - names.begin()]
                                     : bow_frame_labels[v][bow_it - bow_names.begin()];
      if (std::isfinite(slot.x())) {
        return Status::Error(file.path + ": camera " + file.camera + " frame " +
                             std::to_string(frame) + " is labelled twice");
      }
      slot = p.pixel;
      ++matched;
    }
    if (matched == 0) {
      std::string expected;
      for (const auto& n : names) expected += (expected.empty() ? "" : ", ") + n;
      return Status::Error(file.path + ": no label names a point of the " + manifest.instrument +
                           " (" + expected + ")");
    }
  }
  for (const auto& u : unknown) {
    warnings->push_back("label \"" + u + "\" is not a point of the " + manifest.instrument +
                        " (ignored)");
  }
  for (const auto& l : options.labels) labels.files += (labels.files.empty() ? "" : ", ") + l.path;
  return labels;
}

StatusOr<TrackTemplates> MakeTrackTemplates(const TrackStageOptions& options,
                                            const TrackCapture& capture,
                                            const TrackLabels& labels,
                                            TrackStageSummary* summary) {
  const CaptureManifest& manifest = capture.manifest;
  const std::vector<std::string>& names = labels.names;
  const std::vector<std::string>& bow_names = labels.bow_names;
  const std::string& label_files = labels.files;
  TrackTemplates t;
  // The template from the labelled frame with the most views (ties: the earliest).
  int best_views = -1;
  for (const auto& [frame, per_view] : labels.labelled) {
    int n = 0;
    for (const auto& v : per_view)
      n += std::any_of(v.begin(), v.end(), [](const auto& p) { return std::isfinite(p.x()); });
    if (n > best_views) {
      best_views = n;
      t.template_frame = frame;
    }
  }
  const int64_t template_frame = t.template_frame;
  track::FrameLabels frame_labels{names, labels.labelled.at(template_frame)};
  // The trackers' lengths are mm (the bow's slide search, sample step and priors, its
  // minimum length): the world is scaled to mm for them; projections do not change
  // (t and X both times the scale). Outputs are pixels; track.json's 3D points are put
  // back into the calibration's units.
  const std::string calibration_path = ResolveCapturePath(capture.dir, manifest.calibration);
  ARCO_ASSIGN_OR_RETURN(const Calibration calibration,
                        calibration::LoadCalibration(calibration_path));
  const bool one_view = capture.views() == 1;
  if (one_view) {
    // One camera: the instrument's model posed by the labels (PoseTemplateInOneView).
    // One view measures no length, so a calibration without a metric unit is read as mm:
    // with one camera its translation's scale changes nothing that is seen.
    t.mm_per_unit = calibration.rig.units == "m" ? 1000.0 : 1.0;
    if (calibration.rig.units != "m" && calibration.rig.units != "mm")
      summary->warnings.push_back("the calibration " + calibration_path + " is in units '" +
                                  calibration.rig.units +
                                  "': one view measures no length, its units are taken as mm "
                                  "(the instrument's model sets the scale)");
    t.cameras = capture.cameras;
    for (Camera& c : t.cameras) c.cam_from_world.translation *= t.mm_per_unit;
    ARCO_ASSIGN_OR_RETURN(const InstrumentModel model,
                          InstrumentModel::Create(manifest.instrument));
    // The rigid points a one-view pose uses (no end pin: its spike is the player's).
    const std::vector<Eigen::Vector3d> nominal = NominalPoseKeypointsInInstrument(model);
    const std::vector<std::string>& model_names = model.keypoint_names();
    std::vector<Eigen::Vector3d> model_points;
    for (const std::string& n : names) {
      const auto it = std::find(model_names.begin(), model_names.end(), n);
      model_points.push_back(it == model_names.end() ? Eigen::Vector3d::Constant(kNaN)
                                                     : nominal[it - model_names.begin()]);
    }
    StatusOr<track::RigidTemplate> body =
        track::PoseTemplateInOneView(t.cameras[0], frame_labels, model_points);
    if (!body.ok()) return Status::Error(label_files + ": " + body.status().message());
    t.body = std::move(body).value();
  } else {
    StatusOr<track::RigidTemplate> body = track::TriangulateTemplate(capture.cameras, frame_labels);
    if (!body.ok()) return Status::Error(label_files + ": " + body.status().message());
    t.body = std::move(body).value();
    ARCO_ASSIGN_OR_RETURN(t.mm_per_unit,
                          MmPerWorldUnit(calibration.rig.units,
                                         calibration_path,
                                         manifest.instrument,
                                         names,
                                         t.body.points,
                                         label_files));
    t.cameras = capture.cameras;
    for (Camera& c : t.cameras) c.cam_from_world.translation *= t.mm_per_unit;
    for (Eigen::Vector3d& x : t.body.points) x *= t.mm_per_unit;
    t.body.plane_point *= t.mm_per_unit;
  }
  const double mm_per_unit = t.mm_per_unit;
  summary->units = calibration.rig.units;
  summary->mm_per_unit = mm_per_unit;
  summary->template_frame = template_frame;
  summary->label_rms_px = t.body.rms_reprojection_px;
  for (size_t p = 0; p < names.size(); ++p) {
    (std::isfinite(t.body.points[p].x()) ? summary->tracked_points : summary->untracked_points)
        .push_back(names[p]);
  }
  for (const auto& n : summary->untracked_points) {
    summary->warnings.push_back(
        "point " + n +
        (one_view ? " is not labelled or has no place in the model a view poses: left NaN"
                  : " is labelled in fewer than two views: left NaN"));
  }
  // The bow: a thin rigid body from its frog and tip labelled in two views of the
  // template frame; else its slots are kept.
  if (!bow_names.empty() && !options.track_bow) {
    summary->warnings.push_back(
        "the bow is not tracked (track_bow off): its points are kept as they were");
  } else if (!bow_names.empty() && one_view) {
    // One view gives the bow's line in the image, not its depth (monocular_lift.h).
    summary->warnings.push_back(
        "the bow is not tracked from one view (its depth is unknown): its points are kept as "
        "they were");
  } else if (!bow_names.empty()) {
    track::FrameLabels bow_frame_labels{bow_names, labels.bow_labelled.at(template_frame)};
    auto bow = track::TriangulateTemplate(t.cameras, bow_frame_labels, 10, /*thin=*/true);
    size_t bow_points = 0;
    if (bow.ok())
      for (const auto& x : bow->points) bow_points += std::isfinite(x.x());
    if (bow.ok() && bow_points == bow_names.size()) {
      const double length_mm = (bow->points[1] - bow->points[0]).norm();
      if (!(length_mm >= track::kMinBowLengthMm)) {
        return Status::Error(label_files + ": frog and tip are " + FormatNumber(length_mm) +
                             " mm apart in frame " + std::to_string(template_frame) +
                             " (a bow is at least " + FormatNumber(track::kMinBowLengthMm) +
                             " mm long; scale " + FormatNumber(mm_per_unit) + " mm per " +
                             calibration.rig.units + " unit of " + calibration_path + ")");
      }
      t.bow = *bow;
      summary->bow_tracked = true;
    } else {
      summary->warnings.push_back(
          "the bow is not tracked (its frog and tip need labels in two views of frame " +
          std::to_string(template_frame) + "): its points are kept as they were");
    }
  }
  return t;
}

StatusOr<NpyArray<float>> StartTrackKeypoints(const TrackCapture& capture,
                                              TrackStageSummary* summary) {
  const CaptureManifest& manifest = capture.manifest;
  const int64_t views = capture.views(), points = capture.layout->size();
  // The keypoints already there are kept (body and hands from `arco detect`, the bow).
  NpyArray<float> out;
  out.shape = {manifest.frame_count, views, points, 3};
  out.data.assign(static_cast<size_t>(manifest.frame_count * views * points * 3), kNaNf);
  if (!manifest.keypoints2d.empty() && manifest.layout == capture.layout_name) {
    ARCO_RETURN_IF_ERROR(CheckCaptureKeypoints2d(capture.dir, manifest));
    // Each camera's own frames: rewritten as they are.
    ARCO_ASSIGN_OR_RETURN(
        NpyArray<double> old,
        ReadCaptureKeypoints2d(capture.dir, manifest, KeypointTimes::kAsRecorded));
    for (size_t i = 0; i < out.data.size(); ++i) out.data[i] = static_cast<float>(old.data[i]);
    summary->kept_other_points = true;
  }
  return out;
}

StatusOr<TrackRun> TrackCaptureFrames(const TrackStageOptions& options,
                                      const TrackCapture& capture,
                                      const TrackLabels& labels,
                                      const TrackTemplates& templates,
                                      const NpyArray<float>& keypoints,
                                      Progress& progress,
                                      TrackStageSummary* summary) {
  const CaptureManifest& manifest = capture.manifest;
  const int views = capture.views();
  const int64_t first = capture.first, last = capture.last;
  const int64_t template_frame = templates.template_frame;
  const std::vector<Camera>& cameras = templates.cameras;
  // The right hand per view in the pictures read (each view's row of its own frame
  // `camera_frames[v]`, as `arco detect` wrote it): the mean pixel of its points that
  // `arco detect` scored at least bow_hand_min_score, when enough did; NaN otherwise.
  const std::vector<int>* hand_slots = capture.layout->Group("right_hand");
  const auto right_hand = [&](const std::vector<int64_t>& camera_frames,
                              int64_t* frames_with_hand) {
    std::vector<Eigen::Vector2d> px(views, Eigen::Vector2d::Constant(kNaN));
    if (!summary->kept_other_points || hand_slots == nullptr) return px;
    int seen = 0;
    for (int v = 0; v < views; ++v) {
      if (camera_frames[v] < 0) continue;
      const int64_t f = camera_frames[v] - first;
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      int count = 0;
      for (int slot : *hand_slots) {
        const float* x = &keypoints.data[KeypointIndex(capture, f, v, slot)];
        if (!(std::isfinite(x[0]) && std::isfinite(x[1]) && x[2] >= options.bow_hand_min_score))
          continue;
        sum += Eigen::Vector2d(x[0], x[1]);
        ++count;
      }
      if (count >= options.bow_hand_min_points) {
        px[v] = sum / count;
        ++seen;
      }
    }
    *frames_with_hand += seen >= 2;
    return px;
  };

  // Forwards from the labelled frame, then backwards, over the capture's frames: the
  // pose of frame g is solved from every view at once, so the pictures of one solve must
  // be of one moment. A camera off the capture's clock (phones synced by sound) gives its
  // own frame nearest g (CameraFramesNear): its tracks still move from one picture to the
  // next of its video (a frame repeats or is skipped only once in 1 / drift frames), and
  // the views of a solve are at most half a frame apart. Tracking each camera in its own
  // frames and resampling the points afterwards, as `arco detect` may for a detector
  // that sees one view, would solve each pose from pictures up to the offset apart.
  // WriteTrackOutputs puts the points back on each camera's own rows.
  const int threads = ResolveThreadCount(options.num_threads);
  track::InstrumentTrackerOptions tracker_options = options.tracker;
  tracker_options.num_threads = threads;
  TrackRun run;
  std::vector<track::TrackFrame>& results = run.instrument;
  std::vector<track::TrackFrame>& bow_results = run.bow;
  results.resize(static_cast<size_t>(manifest.frame_count));
  bow_results.resize(results.size());
  std::vector<char> done(results.size(), 0);
  const auto track_start = std::chrono::steady_clock::now();
  progress.SetTotal(manifest.frame_count * views);
  for (const int step : {+1, -1}) {
    if (step < 0 && template_frame == first) break;
    track::InstrumentTracker tracker(cameras, templates.body, tracker_options);
    std::optional<track::BowTracker> bow_tracker;
    if (templates.bow) {
      track::BowTrackerOptions bow_options = options.bow;
      bow_options.num_threads = threads;
      bow_tracker.emplace(cameras, templates.bow->points[0], templates.bow->points[1], bow_options);
    }
    track::TrackFrame bow_r;
    Frames frames(manifest, capture.inputs);
    for (int64_t g = template_frame; g >= first && g <= last; g += step) {
      const std::vector<int64_t> camera_frames = CameraFramesNear(capture, g);
      ARCO_ASSIGN_OR_RETURN(std::vector<const media::Image*> images,
                            frames.Read(camera_frames, threads, &summary->decode_s));
      track::TrackFrame r;
      if (g == template_frame) {
        // A view that dropped the labelled frame starts from a blank picture.
        std::vector<media::Image> blanks(views);
        for (int v = 0; v < views; ++v) {
          if (images[v] != nullptr) continue;
          blanks[v] =
              media::MakeImage(cameras[v].width, cameras[v].height, media::PixelFormat::kGray8);
          images[v] = &blanks[v];
        }
        r = tracker.Start(images);
        if (bow_tracker) {
          const auto bow_start = std::chrono::steady_clock::now();
          int64_t with_hand = 0;
          const std::vector<Eigen::Vector2d> hand = right_hand(camera_frames, &with_hand);
          if (step > 0) summary->bow_hand_frames += with_hand;
          bow_r = bow_tracker->Start(images, &hand);
          summary->bow_s += SecondsSince(bow_start);
        }
      } else {
        const auto it = labels.labelled.find(g);
        r = tracker.Next(images, it != labels.labelled.end() ? &it->second : nullptr);
        if (bow_tracker) {
          const auto bow_start = std::chrono::steady_clock::now();
          const auto bow_it = labels.bow_labelled.find(g);
          int64_t with_hand = 0;
          const std::vector<Eigen::Vector2d> hand = right_hand(camera_frames, &with_hand);
          bow_r = bow_tracker->Next(
              images, bow_it != labels.bow_labelled.end() ? &bow_it->second : nullptr, &hand);
          summary->bow_s += SecondsSince(bow_start);
          if (!done[static_cast<size_t>(g - first)]) summary->bow_hand_frames += with_hand;
        }
      }
      const size_t f = static_cast<size_t>(g - first);
      if (!done[f]) {
        results[f] = std::move(r);
        bow_results[f] = std::move(bow_r);
        done[f] = 1;
        progress.Advance(views);
      }
    }
  }
  summary->track_s = SecondsSince(track_start);
  return run;
}

Status WriteTrackOutputs(const TrackStageOptions& options,
                         const TrackCapture& capture,
                         const TrackLabels& labels,
                         const TrackTemplates& templates,
                         const TrackRun& run,
                         NpyArray<float> keypoints,
                         const TrackOutputPaths& paths,
                         TrackStageSummary* summary) {
  const CaptureManifest& manifest = capture.manifest;
  const int views = capture.views();
  const int64_t first = capture.first;
  const std::vector<std::string>& names = labels.names;
  const std::vector<std::string>& bow_names = labels.bow_names;
  const bool bow_tracked = templates.bow.has_value();
  NpyArray<float>& out = keypoints;
  summary->layout = capture.layout_name;
  summary->first_frame = first;
  summary->last_frame = capture.last;
  summary->cameras.resize(views);
  // One tracked point (NaN where not recorded or lost) into slot p of view v in frame f.
  const auto put = [&](int64_t f, int v, int slot, bool recorded, const track::TrackedPoint& q) {
    const size_t k = KeypointIndex(capture, f, v, slot);
    const bool ok = recorded && std::isfinite(q.pixel.x());
    out.data[k] = ok ? static_cast<float>(q.pixel.x()) : kNaNf;
    out.data[k + 1] = ok ? static_cast<float>(q.pixel.y()) : kNaNf;
    out.data[k + 2] = ok ? static_cast<float>(q.score) : kNaNf;
  };
  // Whether view v had a picture for the capture's frame g (the tracker's frames).
  const auto seen = [&](int v, int64_t g) {
    const int64_t own = CameraFramesNear(capture, g)[v];
    return own >= 0 && manifest.VideoFrameNumber(v, own) >= 0;
  };
  Json frames_json = Json::array();
  for (int64_t f = 0; f < manifest.frame_count; ++f) {
    const track::TrackFrame& r = run.instrument[f];
    if (!r.pose_ok) ++summary->frames_without_pose;
    Json view_json = Json::array();
    for (int v = 0; v < views; ++v) {
      const bool recorded = seen(v, first + f);
      const track::ViewTrackReport& vr = r.views[v];
      view_json.push_back(ViewJson(vr));
      TrackCameraSummary& c = summary->cameras[v];
      if (recorded) {
        ++c.frames;
        c.lost_frames += vr.lost;
        c.reacquired += vr.reacquired;
        c.mean_inliers += vr.inliers;
        c.mean_residual_px += vr.residual_px;
      }
      // A camera off the capture's clock: its rows below.
      if (!manifest.cameras[v].OnCaptureClock()) continue;
      for (size_t p = 0; p < names.size(); ++p) {
        put(f, v, (*capture.instrument_slots)[p], recorded, r.points[v][p]);
      }
      for (size_t p = 0; bow_tracked && p < bow_names.size(); ++p) {
        put(f, v, (*capture.bow_slots)[p], recorded, run.bow[f].points[v][p]);
      }
    }
    Json bow_json = nullptr;
    if (bow_tracked) {
      const track::TrackFrame& b = run.bow[f];
      if (!b.pose_ok) ++summary->bow_frames_without_pose;
      Json bow_views = Json::array();
      for (const auto& vr : b.views) bow_views.push_back(ViewJson(vr));
      for (int v = 0; v < views; ++v) {
        if (!seen(v, first + f)) continue;
        summary->cameras[v].bow_lost_frames += b.views[v].lost;
      }
      bow_json = Json{{"pose_ok", b.pose_ok},
                      {"match_ncc", b.match_ncc},
                      {"inliers", b.inliers},
                      {"residual_px", b.residual_px},
                      {"views", bow_views}};
    }
    frames_json.push_back({{"frame", first + f},
                           {"pose_ok", r.pose_ok},
                           {"inliers", r.inliers},
                           {"residual_px", r.residual_px},
                           {"views", view_json},
                           {"bow", bow_json}});
  }
  // keypoints2d.npy's rows of a camera off the capture's clock are its own frames
  // (docs/formats.md, "Cameras synced by sound"): own frame n, exposed at the capture's
  // (fractional) frame c, gets the points tracked at the capture's frames around c,
  // linearly between the two (x and y; the lower score), as ResampleCameraKeypoints
  // samples them, so that readers, which sample the rows back at the capture's frames,
  // get the tracked points (exactly when the offset is a whole number of frames).
  for (int v = 0; v < views; ++v) {
    if (manifest.cameras[v].OnCaptureClock()) continue;
    // CameraFrameAt is affine in the capture's frame: its inverse.
    const double a = manifest.CameraFrameAt(v, 0.0), b = manifest.CameraFrameAt(v, 1.0) - a;
    for (int64_t f = 0; f < manifest.frame_count; ++f) {
      const bool recorded = manifest.VideoFrameNumber(v, first + f) >= 0;
      double row = (static_cast<double>(first + f) - a) / b - static_cast<double>(first);
      // Within half a frame past the first or last capture frame (a drifting clock): the
      // points of that frame, as near as the tracker's pictures are to their moments.
      const double end = static_cast<double>(manifest.frame_count - 1);
      if (row < 0 && row >= -0.5) row = 0;
      if (row > end && row <= end + 0.5) row = end;
      double lower = std::floor(row);
      double w = row - lower;
      if (w < 1e-9) w = 0;  // within a rounding error of a frame: that frame alone
      if (w > 1 - 1e-9) {
        lower += 1;
        w = 0;
      }
      const int64_t i0 = static_cast<int64_t>(lower), i1 = w == 0 ? i0 : i0 + 1;
      const bool inside = lower >= 0 && i1 < manifest.frame_count;
      const auto sample = [&](const std::vector<track::TrackFrame>& frames, size_t p) {
        track::TrackedPoint q;
        q.pixel = Eigen::Vector2d::Constant(kNaN);
        if (!inside) return q;
        const track::TrackedPoint& q0 = frames[i0].points[v][p];
        const track::TrackedPoint& q1 = frames[i1].points[v][p];
        q.pixel = (1 - w) * q0.pixel + w * q1.pixel;
        q.score =
            std::isnan(q0.score) || std::isnan(q1.score) ? kNaN : std::min(q0.score, q1.score);
        return q;
      };
      for (size_t p = 0; p < names.size(); ++p) {
        put(f, v, (*capture.instrument_slots)[p], recorded, sample(run.instrument, p));
      }
      for (size_t p = 0; bow_tracked && p < bow_names.size(); ++p) {
        put(f, v, (*capture.bow_slots)[p], recorded, sample(run.bow, p));
      }
    }
  }
  if (bow_tracked && summary->bow_frames_without_pose > 0) {
    summary->warnings.push_back(
        "the bow was not found in " + std::to_string(summary->bow_frames_without_pose) + " of " +
        std::to_string(manifest.frame_count) +
        " frames: frog and tip are its predicted positions there, with score 0.1");
  }
  for (int v = 0; v < views; ++v) {
    TrackCameraSummary& c = summary->cameras[v];
    c.camera = capture.inputs[v].camera;
    if (c.frames > 0) {
      c.mean_inliers /= c.frames;
      c.mean_residual_px /= c.frames;
    }
  }
  Json template_json = Json::array();
  for (size_t p = 0; p < names.size(); ++p) {
    const Eigen::Vector3d x = templates.body.points[p] / templates.mm_per_unit;
    template_json.push_back(
        {{"name", names[p]},
         {"label_views", templates.body.label_views[p]},
         {"point_in_world",
          std::isfinite(x.x()) ? Json::array({x.x(), x.y(), x.z()}) : Json(nullptr)}});
  }
  ARCO_RETURN_IF_ERROR(WriteNpy(paths.keypoints, out));
  CaptureManifest written = manifest;
  written.keypoints2d = kTrackKeypointsFile;
  written.layout = capture.layout_name;
  written.keypoint_names.clear();
  ARCO_RETURN_IF_ERROR(WriteJsonFile(paths.manifest, CaptureManifestToJson(written)));
  Json report_summary = ToJson(*summary);
  report_summary.erase("decode_s");  // times differ between runs: left out
  report_summary.erase("track_s");
  report_summary.erase("wall_s");
  report_summary.erase("bow_s");
  Json cameras_json = Json::array();
  for (const auto& in : capture.inputs) cameras_json.push_back(in.camera);
  return WriteJsonFile(paths.report,
                       Json{{"format", "arco-track-report"},
                            {"options", ToJson(options)},
                            {"summary", report_summary},
                            {"template", template_json},
                            {"cameras", cameras_json},
                            {"frames", frames_json}});
}

}  // namespace arco::capture
