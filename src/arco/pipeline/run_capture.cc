#include "arco/pipeline/run_capture.h"

#include <chrono>
#include <stdexcept>
#include <utility>

#include "arco/audio/double_stops_csv.h"
#include "arco/hand/hand_params.h"
#include "arco/pipeline/capture_checks.h"
#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/result_folder.h"
#include "arco/util/atomic_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/fingerprint.h"

namespace arco::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void Append(std::vector<std::string>* to, const std::vector<std::string>& from) {
  to->insert(to->end(), from.begin(), from.end());
}

}  // namespace

TriangulateStageOptions RunOptions::ForTriangulate() const {
  TriangulateStageOptions o = triangulate;
  o.capture_dir = capture_dir;
  o.result_dir = result_dir;
  o.triangulation.num_threads = num_threads;
  return o;
}

InstrumentStageOptions RunOptions::ForInstrument() const {
  InstrumentStageOptions o = instrument;
  o.result_dir = result_dir;
  o.num_threads = num_threads;
  return o;
}

HandStageOptions RunOptions::ForHands() const {
  HandStageOptions o = hands;
  o.result_dir = result_dir;
  o.num_threads = num_threads;
  return o;
}

PitchStageOptions RunOptions::ForPitch() const {
  PitchStageOptions o = pitch;
  o.double_stops = double_stops;
  return o;
}

RefineStageOptions RunOptions::ForRefine(refine::RefineMode mode) const {
  RefineStageOptions o;
  o.result_dir = result_dir;
  o.refine = refine;
  o.refine.mode = mode;
  o.refine.num_threads = num_threads;
  return o;
}

Status RunOptions::Validate() const {
  if (num_threads < 0) return Status::Error("num_threads must be >= 0");
  ARCO_RETURN_IF_ERROR(ForTriangulate().Validate().WithContext("triangulate"));
  ARCO_RETURN_IF_ERROR(ForInstrument().Validate().WithContext("instrument"));
  ARCO_RETURN_IF_ERROR(ForHands().Validate().WithContext("hands"));
  ARCO_RETURN_IF_ERROR(ForPitch().Validate().WithContext("pitch"));
  return ForRefine(refine.mode).Validate().WithContext("refine");
}

Json ToJson(const RunOptions& o) {
  Json triangulate = ToJson(o.ForTriangulate());
  triangulate["num_threads"] = o.ForTriangulate().triangulation.num_threads;
  return {{"num_threads", o.num_threads},
          {"overwrite", o.overwrite},
          {"triangulate", triangulate},
          {"instrument", ToJson(o.ForInstrument())},
          {"hands", ToJson(o.ForHands())},
          {"refine", refine::ToJson(o.ForRefine(refine::RefineMode::kArco).refine)}};
}

FolderReplace RunOptions::Replace() const {
  FolderReplace r;
  r.overwrite = overwrite;
  r.marker = kResultManifestName;  // only an arco result folder is replaced
  r.kind = "result folder";
  return r;
}

namespace {

// Every stage, in order, into `result` (options.result_dir's folder, Exclusive: its
// result.json is held, never read back).
StatusOr<RunSummary> RunStages(const RunOptions& options,
                               const ResultFolder& result,
                               CaptureContext capture,
                               Progress& progress) {
  RunSummary summary;
  auto stage = [&](int index, const char* name) {
    progress.StartStage(index, kRunStages, name);
    return Clock::now();
  };

  // Each stage takes the records of the stages before it as made, not read back from
  // the result folder (the files hold the same values), and returns its own, which the
  // run writes through its one ResultFolder.
  auto start = stage(1, "triangulate");
  ARCO_RETURN_IF_ERROR(result.CheckWritable());  // before the work
  ARCO_ASSIGN_OR_RETURN(TriangulateStageResult triangulation,
                        RunTriangulateStage(options.ForTriangulate(), capture, progress));
  ARCO_RETURN_IF_ERROR(WriteTriangulation(result, capture, &triangulation));
  summary.triangulate = triangulation.summary;
  summary.timings.push_back({"triangulate", SecondsSince(start)});

  start = stage(2, "instrument");
  ARCO_ASSIGN_OR_RETURN(
      const InstrumentRecord instrument,
      RunInstrumentStage(options.ForInstrument(), capture, triangulation, progress));
  ARCO_RETURN_IF_ERROR(result.WriteInstrument(instrument));
  summary.instrument = instrument.summary;
  summary.timings.push_back({"instrument", SecondsSince(start)});
  Append(&summary.warnings, summary.instrument.warnings);

  start = stage(3, "hands");
  ARCO_ASSIGN_OR_RETURN(
      HandRecord hand,
      RunHandStage(options.ForHands(), capture, triangulation, instrument, progress));
  ARCO_RETURN_IF_ERROR(result.WriteHand(hand));
  summary.hands = hand.summary;
  summary.timings.push_back({"hands", SecondsSince(start)});
  capture.keypoints2d.reset();  // the last stage that reads the 2D keypoints
  Append(&summary.warnings, summary.hands.warnings);

  start = stage(4, "pitch");
  ARCO_ASSIGN_OR_RETURN(const PitchRecord pitch,
                        RunPitchStage(options.ForPitch(), capture, progress));
  if (pitch.summary.ran) ARCO_RETURN_IF_ERROR(result.WritePitch(pitch));
  summary.pitch = pitch.summary;
  capture.audio_bytes.reset();  // the last stage that decodes the audio (up to 256 MiB)
  if (summary.pitch.ran) summary.timings.push_back({"pitch", SecondsSince(start)});
  Append(&summary.warnings, summary.pitch.warnings);

  // Refinement: vision, then paper and arco when there is pitch. The hands, pitch and
  // notes go through their files' encodings (in memory), so that the run refines exactly
  // what `arco refine` reads from the folder.
  start = stage(5, "refine");
  const std::string pitch_path = result.PitchPath();
  ARCO_ASSIGN_OR_RETURN(
      hand.hands, hand::HandsFromParams(hand::HandParams(hand.hands), result.HandParamsPath()));
  StageRecords records;
  records.fps = capture.manifest.fps;
  records.points3d_in_world = &triangulation.points3d;
  records.instrument = &instrument;
  records.hand = &hand;
  records.model = capture.instrument;
  if (capture.view_to_camera.size() == 1) {
    records.one_view_camera_centre_in_world =
        capture.calibration.rig.cameras.at(static_cast<size_t>(capture.view_to_camera[0]))
            .CenterInWorld();
  }
  std::vector<audio::PitchFrame> pitch_as_written;
  if (summary.pitch.ran) {
    ARCO_ASSIGN_OR_RETURN(pitch_as_written,
                          audio::ParsePitchCsv(audio::FormatPitchCsv(pitch.frames), pitch_path));
    records.pitch = &pitch_as_written;
    ARCO_ASSIGN_OR_RETURN(records.notes,
                          audio::ParseNotesCsv(audio::FormatNotesCsv(pitch.notes), pitch_path));
  }
  std::vector<audio::PolyPitchFrame> double_stops_as_written;
  if (!pitch.double_stops.empty()) {
    ARCO_ASSIGN_OR_RETURN(
        double_stops_as_written,
        audio::ParseDoubleStopsCsv(audio::FormatDoubleStopsCsv(pitch.double_stops), pitch_path));
  }
  ARCO_ASSIGN_OR_RETURN(RefineInputs inputs, MakeRefineInputs(options.result_dir, records));
  if (!double_stops_as_written.empty()) AddDoubleStops(double_stops_as_written, &inputs);
  std::vector<refine::RefineMode> modes = {refine::RefineMode::kVision};
  if (inputs.has_pitch) {
    modes.push_back(refine::RefineMode::kPaper);
    modes.push_back(refine::RefineMode::kArco);
  }
  progress.SetTotal(static_cast<int64_t>(modes.size()));
  for (refine::RefineMode mode : modes) {
    const RefineStageOptions ro = options.ForRefine(mode);
    ARCO_ASSIGN_OR_RETURN(const MethodRecord method, RefineMethod(inputs, ro.refine));
    ARCO_RETURN_IF_ERROR(result.WriteMethod(method));
    summary.methods.push_back(method.summary);
    progress.Advance(1);
  }
  summary.timings.push_back({"refine", SecondsSince(start)});
  return summary;
}

// PreflightRun's checks after the capture is opened.
StatusOr<CaptureContext> PreflightOpened(const RunOptions& options, CaptureContext capture) {
  const CaptureManifest& m = capture.manifest;
  ARCO_RETURN_IF_ERROR(LoadCaptureCalibration(&capture));
  // Read once here, checked, parsed and fingerprinted from the same bytes; the stages of
  // the run use the array (CaptureContext::keypoints2d).
  {
    ARCO_ASSIGN_OR_RETURN(const FileBytes bytes,
                          ReadCaptureKeypoints2dBytes(options.capture_dir, m));
    ARCO_ASSIGN_OR_RETURN(NpyArray<double> k,
                          ParseCaptureKeypoints2d(bytes.view(), options.capture_dir, m));
    capture.keypoints2d = std::make_shared<const NpyArray<double>>(std::move(k));
    capture.inputs[kKeypoints2dInput] = {m.keypoints2d, FingerprintBytes(bytes.view())};
  }
  ARCO_RETURN_IF_ERROR(CheckCaptureInstrumentPoints(capture));
  ARCO_RETURN_IF_ERROR(CheckTriangulationFilters(
      options.ForTriangulate(), capture.layout, m.fps, CaptureManifestPath(options.capture_dir)));
  // The audio is read once; the check, its fingerprint and the pitch stage use the bytes.
  ReadCaptureAudioBytes(&capture);
  ARCO_RETURN_IF_ERROR(CheckCaptureAudio(capture).status());
  // The manifest's, the calibration's, the keypoints' and the audio's fingerprints were
  // taken of the bytes parsed; an audio file too large to hold is hashed from disk, after
  // its check (so that a bad file gets its own message rather than the hash's).
  if (capture.audio_bytes) {
    capture.inputs[kAudioInput] = {m.audio, FingerprintBytes(*capture.audio_bytes)};
  } else {
    ARCO_ASSIGN_OR_RETURN(const CaptureInputs audio,
                          FingerprintCaptureInputs(options.capture_dir, m, {kAudioInput}));
    capture.inputs.insert(audio.begin(), audio.end());
  }
  return capture;
}

// PreflightRun on an opened capture, its options validated.
StatusOr<CaptureContext> PreflightValidated(const RunOptions& options, CaptureContext opened) {
  if (opened.capture_dir != options.capture_dir) {
    throw std::invalid_argument("PreflightRun: capture " + opened.capture_dir +
                                " opened for capture_dir " + options.capture_dir);
  }
  ARCO_RETURN_IF_ERROR(CheckOutputFolder(options.result_dir, options.Replace()));
  return PreflightOpened(options, std::move(opened));
}

// The stages of a preflighted capture.
StatusOr<RunSummary> RunPreflighted(const RunOptions& options,
                                    CaptureContext capture,
                                    Progress& progress) {
  // The stages fill a hidden temporary result folder, moved into place once all are done:
  // a failed run leaves no result folder and an old one as it was.
  RunSummary summary;
  ARCO_RETURN_IF_ERROR(AtomicWriteDirectory(
      options.result_dir, options.Replace(), [&](const std::string& tmp_dir) -> Status {
        RunOptions staged = options;
        staged.result_dir = tmp_dir;
        // The one ResultFolder of the run: every stage writes through it (or its copies),
        // which hold result.json as last written.
        const ResultFolder result = ResultFolder::Exclusive(tmp_dir);
        StatusOr<RunSummary> ran = RunStages(staged, result, std::move(capture), progress);
        if (!ran.ok()) {
          // Messages name the result folder the user gave, not its temporary.
          std::string message = ran.status().message();
          const std::string given = NormalizeOutputPath(options.result_dir);
          for (size_t at = message.find(tmp_dir); at != std::string::npos;
               at = message.find(tmp_dir, at + given.size())) {
            message.replace(at, tmp_dir.size(), given);
          }
          return Status::Error(message);
        }
        summary = std::move(ran).value();
        return result.WriteRunOptions(ToJson(options));
      }));
  return summary;
}

}  // namespace

StatusOr<CaptureContext> PreflightRun(const RunOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_RETURN_IF_ERROR(CheckOutputFolder(options.result_dir, options.Replace()));
  ARCO_ASSIGN_OR_RETURN(CaptureContext capture, OpenCapture(options.capture_dir));
  return PreflightOpened(options, std::move(capture));
}

StatusOr<CaptureContext> PreflightRun(const RunOptions& options, CaptureContext opened) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  return PreflightValidated(options, std::move(opened));
}

StatusOr<RunSummary> RunCapture(const RunOptions& options, Progress& progress) {
  // The one validation of the run's options.
  ARCO_ASSIGN_OR_RETURN(const Validated<RunOptions> valid, Validated<RunOptions>::Check(options));
  return RunCapture(valid, progress);
}

StatusOr<RunSummary> RunCapture(const Validated<RunOptions>& options, Progress& progress) {
  // Every input checked before the first stage (and before the result folder exists).
  ARCO_RETURN_IF_ERROR(CheckOutputFolder(options->result_dir, options->Replace()));
  ARCO_ASSIGN_OR_RETURN(CaptureContext capture, OpenCapture(options->capture_dir));
  ARCO_ASSIGN_OR_RETURN(capture, PreflightOpened(*options, std::move(capture)));
  return RunPreflighted(*options, std::move(capture), progress);
}

StatusOr<RunSummary> RunCapture(const Validated<RunOptions>& options,
                                CaptureContext opened,
                                Progress& progress) {
  ARCO_ASSIGN_OR_RETURN(CaptureContext capture, PreflightValidated(*options, std::move(opened)));
  return RunPreflighted(*options, std::move(capture), progress);
}

}  // namespace arco::pipeline
