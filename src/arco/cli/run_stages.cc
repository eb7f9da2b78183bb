// Stages 2-4 of `arco run` (run.h): instrument, hands, pitch.
#include "arco/cli/run_stages.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "arco/audio/notes.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/calibration/calibration_file.h"
#include "arco/hand/kinematics.h"
#include "arco/util/file_io.h"
#include "arco/util/parallel.h"

namespace arco::cli::internal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kLeftHandFirst = 91;
constexpr int kLeftShoulder = 5, kRightShoulder = 6;

std::string Format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), fmt, a, b, c, d);
  return buf;
}

Eigen::Vector3d PointAt(const NpyArray<double>& a, int64_t f, int64_t p) {
  return Eigen::Vector3d(a.at(f, p, 0), a.at(f, p, 1), a.at(f, p, 2));
}

}  // namespace

StatusOr<double> WorldUnitsPerMm(const Json& manifest, const std::string& result_dir) {
  const double s =
      manifest.contains("stages") && manifest["stages"].contains("instrument")
          ? JsonNumberOrNaN(manifest["stages"]["instrument"].value("world_units_per_mm", Json()))
          : kNaN;
  if (!(s > 0)) {
    return Status::Error(JoinPath(result_dir, "result.json") +
                         ": no instrument stage with world_units_per_mm (run `arco run` first)");
  }
  return s;
}

StatusOr<CaptureContext> OpenCapture(const std::string& capture_dir) {
  CaptureContext c;
  c.capture_dir = capture_dir;
  ARCO_ASSIGN_OR_RETURN(c.manifest, ReadCaptureManifest(capture_dir));
  const std::string where = JoinPath(capture_dir, kCaptureManifestName);
  ARCO_ASSIGN_OR_RETURN(c.layout, c.manifest.Layout());
  if (c.manifest.instrument == "none" || c.manifest.instrument.empty()) {
    return Status::Error(where + ": the capture names no instrument; arco run needs one");
  }
  ARCO_ASSIGN_OR_RETURN(InstrumentKind kind, ParseInstrumentKind(c.manifest.instrument));
  InstrumentOptions io;
  io.kind = kind;
  io.tuning.a4_hz = c.manifest.tuning_a4_hz;
  StatusOr<InstrumentModel> model = InstrumentModel::Create(io);
  if (!model.ok()) return model.status().WithContext(where);
  c.instrument = std::make_shared<const InstrumentModel>(std::move(model).value());
  for (const std::string& name : c.instrument->keypoint_names()) {
    if (c.layout.Find(name) < 0) {
      return Status::Error(where + ": layout " + c.layout.name + " has no instrument point " +
                           name);
    }
  }
  if (c.layout.size() < kLeftHandFirst + hand::kNumHandKeypoints) {
    return Status::Error(where + ": layout " + c.layout.name + " has no whole-body hands");
  }
  return c;
}

StatusOr<StageReport> RunInstrumentStage(const RunOptions& options,
                                         const CaptureContext& capture,
                                         std::vector<std::string>* warnings) {
  const std::string& result_dir = options.result_dir;
  ARCO_ASSIGN_OR_RETURN(Json manifest, ReadResultManifest(result_dir));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> points, ReadResultPoints3d(result_dir, "triangulation"));
  const InstrumentModel& model = *capture.instrument;
  const int64_t frames = points.shape[0];
  const int num_k = static_cast<int>(model.keypoint_names().size());
  std::vector<int> columns;
  for (const std::string& name : model.keypoint_names())
    columns.push_back(capture.layout.Find(name));
  std::vector<Eigen::Matrix3Xd> keypoints(static_cast<size_t>(frames));
  std::vector<FrontHint> hints(static_cast<size_t>(frames));
  for (int64_t f = 0; f < frames; ++f) {
    Eigen::Matrix3Xd& m = keypoints[static_cast<size_t>(f)];
    m.resize(3, num_k);
    for (int k = 0; k < num_k; ++k) m.col(k) = PointAt(points, f, columns[static_cast<size_t>(k)]);
    // The performer sits behind the instrument: the shoulders' midpoint says where the
    // back is (strings.h FrontHint).
    hints[static_cast<size_t>(f)].kind = FrontHint::Kind::kPerformerPoint;
    hints[static_cast<size_t>(f)].value =
        0.5 * (PointAt(points, f, kLeftShoulder) + PointAt(points, f, kRightShoulder));
  }
  InstrumentFitOptions fit_options = options.instrument;
  const std::string units = manifest.value("units", "unknown");
  if (units == "mm") fit_options.scale = InstrumentFitOptions::Scale::kWorldIsMillimetres;
  fit_options.num_threads = options.num_threads;
  StatusOr<InstrumentFit> fit = FitInstrument(model, keypoints, hints, fit_options);
  if (!fit.ok()) return fit.status().WithContext("instrument fit");
  const std::vector<InstrumentFramePose> poses = SmoothFramePoses(fit->frames, options.smoothing);
  for (const std::string& w : fit->summary.warnings) warnings->push_back("instrument: " + w);
  if (fit->instrument.order.ambiguous) {
    warnings->push_back("instrument: string order ambiguous: " + fit->instrument.order.warning);
  }
  const double s = fit->instrument.world_units_per_mm;
  // Strings (F, 4, 2, 3) and the placed template keypoints (F, K, 3), world scaled to mm.
  NpyArray<double> strings, placed;
  strings.shape = {frames, model.num_strings(), 2, 3};
  strings.data.assign(static_cast<size_t>(frames * model.num_strings() * 6), kNaN);
  placed.shape = {frames, num_k, 3};
  placed.data.assign(static_cast<size_t>(frames * num_k * 3), kNaN);
  int with_pose = 0;
  for (int64_t f = 0; f < frames; ++f) {
    const InstrumentFramePose& p = poses[static_cast<size_t>(f)];
    if (!p.has_pose()) continue;
    ++with_pose;
    const std::vector<StringSegment> seg = StringsAt(fit->instrument, p.pose);
    for (int i = 0; i < model.num_strings(); ++i) {
      for (int c = 0; c < 3; ++c) {
        strings.at(f, i, 0, c) = seg[static_cast<size_t>(i)].nut[c] / s;
        strings.at(f, i, 1, c) = seg[static_cast<size_t>(i)].bridge[c] / s;
      }
    }
    for (int k = 0; k < num_k; ++k) {
      const Eigen::Vector3d& t = fit->instrument.keypoints_in_instrument[static_cast<size_t>(k)];
      if (!t.allFinite()) continue;
      const Eigen::Vector3d w = p.pose.ToWorld(t) / s;
      for (int c = 0; c < 3; ++c) placed.at(f, k, c) = w[c];
    }
  }
  const InstrumentFitSummary& fs = fit->summary;
  Json entry = {{"files", {{"strings", "strings.npy"}, {"keypoints", "keypoints.npy"}}},
                {"instrument", model.name()},
                {"a4_hz", capture.manifest.tuning_a4_hz},
                {"world_units_per_mm", s},
                {"units", "mm"},
                {"keypoint_names", model.keypoint_names()},
                {"summary",
                 {{"frames", frames},
                  {"frames_with_pose", with_pose},
                  {"frames_high_residual", fs.frames_high_residual},
                  {"median_rms_residual_mm", JsonFromDouble(fs.median_rms_residual_mm)},
                  {"front_agreement", JsonFromDouble(fs.front_agreement)},
                  {"string_order_ambiguous", fit->instrument.order.ambiguous},
                  {"labels_agree", fit->instrument.order.labels_agree}}}};
  ARCO_RETURN_IF_ERROR(refine::WriteStageFolder(
      result_dir,
      "instrument",
      [&](const std::string& dir) -> Status {
        ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, "strings.npy"), strings));
        return WriteNpy(JoinPath(dir, "keypoints.npy"), placed);
      },
      entry));
  StageReport report;
  report.name = "instrument";
  report.summary = Format("%.0f of %.0f frames with a pose, median residual %.2f mm",
                          with_pose,
                          static_cast<double>(frames),
                          fs.median_rms_residual_mm) +
                   Format(", scale %.4g units/mm", s);
  return report;
}

StatusOr<StageReport> RunHandStage(const RunOptions& options,
                                   const CaptureContext& capture,
                                   const RunProgress& progress,
                                   std::vector<std::string>* warnings) {
  const std::string& result_dir = options.result_dir;
  ARCO_ASSIGN_OR_RETURN(Json manifest, ReadResultManifest(result_dir));
  ARCO_ASSIGN_OR_RETURN(const double s, WorldUnitsPerMm(manifest, result_dir));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> points, ReadResultPoints3d(result_dir, "triangulation"));
  const CaptureManifest& m = capture.manifest;
  const std::string calibration_path = ResolveCapturePath(capture.capture_dir, m.calibration);
  ARCO_ASSIGN_OR_RETURN(Calibration calibration, LoadCalibration(calibration_path));
  // The views' cameras with the world scaled to mm (projection is unchanged: t / s).
  std::vector<Camera> cameras;
  for (const CaptureCamera& cam : m.cameras) {
    int c = calibration.rig.FindCamera(cam.name);
    if (c < 0 && !cam.serial.empty()) c = calibration.rig.FindCamera(cam.serial);
    if (c < 0) return Status::Error(calibration_path + ": no camera \"" + cam.name + "\"");
    Camera camera = calibration.rig.cameras[static_cast<size_t>(c)];
    camera.cam_from_world_translation /= s;
    cameras.push_back(camera);
  }
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> k2d, ReadCaptureKeypoints2d(capture.capture_dir, m));
  const int64_t frames = points.shape[0];
  const int64_t views = static_cast<int64_t>(cameras.size());
  std::vector<hand::HandPointsMm> left(static_cast<size_t>(frames));
  for (int64_t f = 0; f < frames; ++f) {
    for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
      left[static_cast<size_t>(f)][k] = PointAt(points, f, kLeftHandFirst + k) / s;
    }
  }
  const hand::HandModel prior = hand::HandModel::Default(hand::HandSide::kLeft);
  hand::HandModel model = prior;
  StatusOr<hand::BoneLengthEstimate> bones = hand::EstimateBoneLengths(left, prior, options.bones);
  if (bones.ok()) {
    StatusOr<hand::HandModel> sized = prior.WithBoneLengths(bones->lengths_mm);
    if (sized.ok()) model = *sized;
  } else {
    warnings->push_back("hand: default bone lengths (" + bones.status().message() + ")");
  }
  const int chunk = std::max(1, options.hand_chunk_frames);
  const int64_t num_chunks = (frames + chunk - 1) / chunk;
  std::vector<std::optional<hand::HandPose>> fitted(static_cast<size_t>(frames));
  std::vector<double> residual_px(static_cast<size_t>(frames), kNaN);
  std::vector<double> median_residual_px(static_cast<size_t>(frames), kNaN);
  if (progress.on_total) progress.on_total(frames);
  ParallelFor(
      num_chunks,
      options.num_threads,
      [&](int64_t ci, int) {
        std::optional<hand::HandPose> previous;
        const int64_t end = std::min(frames, (ci + 1) * chunk);
        for (int64_t f = ci * chunk; f < end; ++f) {
          std::vector<hand::HandKeypoints2d> obs(static_cast<size_t>(views));
          for (int64_t v = 0; v < views; ++v) {
            for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
              const int64_t p = kLeftHandFirst + k;
              obs[static_cast<size_t>(v)].pixels[k] =
                  Eigen::Vector2d(k2d.at(f, v, p, 0), k2d.at(f, v, p, 1));
              const double score = k2d.at(f, v, p, 2);
              obs[static_cast<size_t>(v)].scores[k] = std::isfinite(score) ? score : 0.0;
            }
          }
          hand::HandFitInit init;
          init.points_in_world_mm = left[static_cast<size_t>(f)];
          init.previous_pose = previous;
          const hand::HandFitResult r =
              hand::FitHandMultiView(model, cameras, obs, init, options.hand_fit);
          if (r.ok) {
            fitted[static_cast<size_t>(f)] = r.pose;
            residual_px[static_cast<size_t>(f)] = r.rms_residual_px;
            median_residual_px[static_cast<size_t>(f)] = r.median_residual_px;
            previous = r.pose;
          }
        }
        if (progress.on_advance) progress.on_advance(end - ci * chunk);
      },
      1);
  int ok = 0;
  // Per frame: the RMS (dominated by the few outlier detections a robust fit
  // ignores) and the median residual; the report gives the median over frames of both.
  std::vector<double> res, res_median;
  for (int64_t f = 0; f < frames; ++f) {
    if (!fitted[static_cast<size_t>(f)]) continue;
    ++ok;
    res.push_back(residual_px[static_cast<size_t>(f)]);
    res_median.push_back(median_residual_px[static_cast<size_t>(f)]);
  }
  std::sort(res.begin(), res.end());
  std::sort(res_median.begin(), res_median.end());
  const double median_px = res.empty() ? kNaN : res[res.size() / 2];
  const double median_median_px = res_median.empty() ? kNaN : res_median[res_median.size() / 2];
  NpyArray<double> lengths;
  lengths.shape = {hand::kNumHandKeypoints};
  for (int k = 0; k < hand::kNumHandKeypoints; ++k)
    lengths.data.push_back(k == 0 ? 0.0 : model.bone_length_mm(k));
  Json entry = {
      {"files", {{"hand_params", "hand_params.npy"}, {"bone_lengths_mm", "bone_lengths_mm.npy"}}},
      {"side", "left"},
      {"units", "mm"},
      {"summary",
       {{"frames", frames},
        {"frames_fitted", ok},
        {"median_rms_residual_px", JsonFromDouble(median_px)},
        {"median_residual_px", JsonFromDouble(median_median_px)},
        {"bone_lengths_from_data", bones.ok()}}}};
  ARCO_RETURN_IF_ERROR(refine::WriteStageFolder(
      result_dir,
      "hand",
      [&](const std::string& dir) -> Status {
        ARCO_RETURN_IF_ERROR(
            WriteNpy(JoinPath(dir, "hand_params.npy"), refine::HandParams(fitted)));
        return WriteNpy(JoinPath(dir, "bone_lengths_mm.npy"), lengths);
      },
      entry));
  StageReport report;
  report.name = "hands";
  report.summary = Format(
      "left hand fitted on %.0f of %.0f frames, reprojection median %.2f px (RMS %.2f px, "
      "outliers included)",
      ok,
      static_cast<double>(frames),
      median_median_px,
      median_px);
  return report;
}

StatusOr<StageReport> RunPitchStage(const RunOptions& options,
                                    const CaptureContext& capture,
                                    const RunProgress& progress,
                                    std::vector<std::string>* warnings) {
  const CaptureManifest& m = capture.manifest;
  StageReport report;
  if (m.audio.empty()) {
    warnings->push_back("pitch: the capture has no audio; only the vision method is written");
    return report;
  }
  std::string range_name = capture.instrument->name();
  if (capture.instrument->kind() == InstrumentKind::kDoubleBass) range_name = "bass";
  ARCO_ASSIGN_OR_RETURN(audio::InstrumentRange range, audio::InstrumentRangeByName(range_name));
  audio::PitchTrackerOptions po;
  po.range = range;
  po.fps = m.fps;
  po.start_s = m.audio_offset_s;
  po.max_frames = m.frame_count;
  po.a4_hz = m.tuning_a4_hz;
  ARCO_RETURN_IF_ERROR(po.Validate());
  const std::string audio_path = ResolveCapturePath(capture.capture_dir, m.audio);
  audio::PitchSummary summary;
  if (progress.on_total) progress.on_total(1000);
  int64_t shown = 0;
  ARCO_ASSIGN_OR_RETURN(audio::PitchTrack track,
                        audio::TrackPitchFile(audio_path, po, &summary, [&](double fraction) {
                          const int64_t now = static_cast<int64_t>(fraction * 1000);
                          if (now > shown && progress.on_advance) progress.on_advance(now - shown);
                          shown = std::max(shown, now);
                        }));
  // One row per video frame of the capture (audio shorter than the video: unvoiced).
  std::vector<audio::PitchFrame> frames = track.frames;
  frames.resize(static_cast<size_t>(std::max<int64_t>(0, m.frame_count)));
  for (size_t i = track.frames.size(); i < frames.size(); ++i) {
    frames[i].frame = static_cast<int64_t>(i);
    frames[i].time_s = m.audio_offset_s + static_cast<double>(i) / m.fps;
  }
  if (track.frames.size() < frames.size()) {
    warnings->push_back("pitch: the audio ends before the video; later frames are unvoiced");
  }
  for (const std::string& w : summary.warnings) warnings->push_back("pitch: " + w);
  audio::NoteOptions note_options;
  note_options.a4_hz = m.tuning_a4_hz;
  const audio::NoteAnalysis notes = audio::SegmentNotes(track.fine, track.fine_fps, note_options);
  // pitch.csv and notes.csv go to the result folder itself, where `arco eval` and users
  // look for them (docs/formats.md).
  ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(JoinPath(options.result_dir, "pitch.csv"), frames));
  ARCO_RETURN_IF_ERROR(audio::WriteNotesCsv(JoinPath(options.result_dir, "notes.csv"), notes));
  ARCO_RETURN_IF_ERROR(
      refine::RecordStage(options.result_dir,
                          "pitch",
                          {{"dir", "."},
                           {"files", {{"pitch", "pitch.csv"}, {"notes", "notes.csv"}}},
                           {"a4_hz", m.tuning_a4_hz},
                           {"audio", audio_path},
                           {"summary",
                            {{"duration_s", summary.duration_s},
                             {"voiced_fraction", summary.voiced_fraction},
                             {"notes", notes.notes.size()}}}}));
  report.name = "pitch";
  report.summary = Format("%.1f s of audio, %.0f%% voiced, %.0f notes",
                          summary.duration_s,
                          100.0 * summary.voiced_fraction,
                          static_cast<double>(notes.notes.size()));
  return report;
}

}  // namespace arco::cli::internal
