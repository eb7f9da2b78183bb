#include "arco/pipeline/run_capture.h"

#include <chrono>
#include <functional>
#include <future>
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
#include "arco/util/parallel.h"

namespace arco::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void Append(std::vector<std::string>* to, const std::vector<std::string>& from) {
  to->insert(to->end(), from.begin(), from.end());
}

// The run's summary from its records: every stage's summary, the warnings in the stages'
// order.
void Summarize(const RunRecords& records, RunSummary* summary) {
  summary->triangulate = records.triangulation.summary;
  summary->instrument = records.instrument.summary;
  summary->hands = records.hand.summary;
  summary->pitch = records.pitch.summary;
  for (const MethodRecord& method : records.methods) summary->methods.push_back(method.summary);
  Append(&summary->warnings, summary->instrument.warnings);
  Append(&summary->warnings, summary->hands.warnings);
  Append(&summary->warnings, summary->pitch.warnings);
}

// Writes the records of a run in the order given, each when its stage has made it. With
// more than one thread the writes run on a thread of their own, one after the other, while
// the next stage computes (a one-minute take writes about 40 MB, which otherwise waited for
// the last stage); with one thread each is written at once. Either way the folder is
// written in the same order, so it is the same byte for byte. A failed write stops the
// later ones; Finish returns the first failure. Whatever a write reads must stay alive and
// unchanged until Finish.
class OrderedWriter {
 public:
  explicit OrderedWriter(bool beside) : beside_(beside) {}
  OrderedWriter(const OrderedWriter&) = delete;
  OrderedWriter& operator=(const OrderedWriter&) = delete;
  ~OrderedWriter() {
    if (last_.valid()) last_.wait();
  }

  void Write(std::function<Status()> write) {
    if (!beside_) {
      if (status_.ok()) status_ = write();
      return;
    }
    last_ = std::async(std::launch::async,
                       [previous = std::move(last_), write = std::move(write)]() mutable {
                         if (previous.valid()) {
                           Status before = previous.get();
                           if (!before.ok()) return before;
                         }
                         return write();
                       });
  }

  // Waits for every write; the first failure, or Ok.
  Status Finish() {
    if (last_.valid()) status_ = last_.get();
    return status_;
  }

 private:
  bool beside_;
  Status status_ = Status::Ok();
  std::future<Status> last_;
};

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

// Every stage, in order, each taking the records of the stages before it as made (not read
// back from the result folder: the files hold the same values) and returning its own;
// each record is written into `result` once made (OrderedWriter), all of them by the time
// this returns.
StatusOr<RunRecords> RunStages(const RunOptions& options,
                               CaptureContext* opened,
                               const ResultFolder& result,
                               Progress& progress,
                               RunSummary* summary) {
  CaptureContext& capture = *opened;
  RunRecords records;
  const bool threads = ResolveThreadCount(options.num_threads) > 1;
  // Declared after `records`, so that on an early return it waits for its writes before
  // the records they read are destroyed.
  OrderedWriter writer(threads);
  auto stage = [&](int index, const char* name) {
    progress.StartStage(index, kRunStages, name);
    return Clock::now();
  };

  // The pitch stage reads only the audio and the manifest, so with more than one thread
  // it runs beside stages 1-3 on a thread of its own (silently: the progress shows the
  // stages in order, and the pitch's line when it is joined). Its record does not depend
  // on when it runs, so the outputs stay those of one thread, bit for bit.
  struct TimedPitch {
    StatusOr<PitchRecord> record;
    double seconds = 0;
  };
  auto run_pitch = [&options, &capture](Progress& pitch_progress) {
    const auto pitch_start = Clock::now();
    StatusOr<PitchRecord> record = RunPitchStage(options.ForPitch(), capture, pitch_progress);
    return TimedPitch{std::move(record), SecondsSince(pitch_start)};
  };
  std::future<TimedPitch> pitch_beside;
  if (threads) {
    pitch_beside = std::async(std::launch::async, run_pitch, std::ref(NoProgress()));
  }

  auto start = stage(1, "triangulate");
  ARCO_ASSIGN_OR_RETURN(records.triangulation,
                        RunTriangulateStage(options.ForTriangulate(), capture, progress));
  summary->timings.push_back({"triangulate", SecondsSince(start)});
  // The stages after it read the filtered points only; the write releases the raw ones.
  writer.Write([&] { return WriteTriangulation(result, capture, &records.triangulation); });

  start = stage(2, "instrument");
  ARCO_ASSIGN_OR_RETURN(
      records.instrument,
      RunInstrumentStage(options.ForInstrument(), capture, records.triangulation, progress));
  summary->timings.push_back({"instrument", SecondsSince(start)});
  writer.Write([&] { return result.WriteInstrument(records.instrument); });

  start = stage(3, "hands");
  ARCO_ASSIGN_OR_RETURN(
      records.hand,
      RunHandStage(
          options.ForHands(), capture, records.triangulation, records.instrument, progress));
  summary->timings.push_back({"hands", SecondsSince(start)});
  writer.Write([&] { return result.WriteHand(records.hand); });
  capture.keypoints2d.reset();  // the last stage that reads the 2D keypoints

  stage(4, "pitch");
  const bool beside = pitch_beside.valid();
  TimedPitch pitch = beside ? pitch_beside.get() : run_pitch(progress);
  ARCO_ASSIGN_OR_RETURN(records.pitch, std::move(pitch.record));
  capture.audio_bytes.reset();  // the last stage that decodes the audio (up to 256 MiB)
  if (records.pitch.summary.ran) {
    summary->timings.push_back({"pitch", pitch.seconds, beside});
    writer.Write([&] { return result.WritePitch(records.pitch); });
  }

  start = stage(5, "refine");
  StatusOr<std::vector<MethodRecord>> methods =
      RunRefineMethods(options, capture, records, progress, [&](const MethodRecord& method) {
        writer.Write([&result, &method] { return result.WriteMethod(method); });
      });
  // A failed stage's error first, as when every record was written after the stages.
  if (!methods.ok()) return methods.status();
  ARCO_RETURN_IF_ERROR(writer.Finish());
  summary->timings.push_back({"refine", SecondsSince(start)});
  records.methods = std::move(*methods);
  return records;
}

// PreflightRun's checks after the capture is opened.
StatusOr<CaptureContext> PreflightOpened(const RunOptions& options, CaptureContext capture) {
  const CaptureManifest& m = capture.manifest;
  ARCO_RETURN_IF_ERROR(LoadCaptureCalibration(&capture));
  // Read once here; the stages of the run use the array (CaptureContext::keypoints2d).
  ARCO_RETURN_IF_ERROR(LoadCaptureKeypoints2d(&capture));
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

// Writes `result_dir` as one folder (a hidden temporary, moved into place when complete: a
// failure leaves no result folder and an old one as it was) through one Exclusive
// ResultFolder, which `fill` writes into. Messages name the result folder the user gave,
// not its temporary.
Status WriteResultFolder(
    const RunOptions& options,
    const std::function<Status(const RunOptions& staged, const ResultFolder& result)>& fill) {
  return AtomicWriteDirectory(
      options.result_dir, options.Replace(), [&](const std::string& tmp_dir) -> Status {
        RunOptions staged = options;
        staged.result_dir = tmp_dir;
        // The one ResultFolder of the run: every record is written through it, which holds
        // result.json as last written.
        const ResultFolder result = ResultFolder::Exclusive(tmp_dir);
        Status filled = fill(staged, result);
        if (!filled.ok()) {
          std::string message = filled.message();
          const std::string given = NormalizeOutputPath(options.result_dir);
          for (size_t at = message.find(tmp_dir); at != std::string::npos;
               at = message.find(tmp_dir, at + given.size())) {
            message.replace(at, tmp_dir.size(), given);
          }
          return Status::Error(message);
        }
        return result.WriteRunOptions(ToJson(options));
      });
}

// The stages of a preflighted capture, their records written as made.
StatusOr<RunSummary> RunPreflighted(const RunOptions& options,
                                    CaptureContext capture,
                                    Progress& progress) {
  RunSummary summary;
  ARCO_RETURN_IF_ERROR(WriteResultFolder(
      options, [&](const RunOptions& staged, const ResultFolder& result) -> Status {
        ARCO_RETURN_IF_ERROR(result.CheckWritable());  // before the work
        // The stages release the 2D keypoints and the audio from the context once read for
        // the last time; the writers need only its manifest, layout and inputs.
        ARCO_ASSIGN_OR_RETURN(RunRecords records,
                              RunStages(staged, &capture, result, progress, &summary));
        Summarize(records, &summary);
        return Status::Ok();
      }));
  return summary;
}

}  // namespace

StatusOr<std::vector<MethodRecord>> RunRefineMethods(
    const RunOptions& options,
    const CaptureContext& capture,
    const RunRecords& records,
    Progress& progress,
    const std::function<void(const MethodRecord&)>& made) {
  // The hands, pitch and notes go through their files' encodings (in memory), so that the
  // run refines exactly what `arco refine` reads from the folder.
  const ResultFolder result(options.result_dir);
  const std::string pitch_path = result.PitchPath();
  HandRecord hand = records.hand;
  ARCO_ASSIGN_OR_RETURN(
      hand.hands, hand::HandsFromParams(hand::HandParams(hand.hands), result.HandParamsPath()));
  StageRecords stages;
  stages.fps = capture.manifest.fps;
  stages.points3d_in_world = &records.triangulation.points3d;
  stages.instrument = &records.instrument;
  stages.hand = &hand;
  stages.model = capture.instrument;
  if (capture.view_to_camera.size() == 1) {
    stages.one_view_camera_centre_in_world =
        capture.calibration.rig.cameras.at(static_cast<size_t>(capture.view_to_camera[0]))
            .CenterInWorld();
  }
  const PitchRecord& pitch = records.pitch;
  std::vector<audio::PitchFrame> pitch_as_written;
  if (pitch.summary.ran) {
    ARCO_ASSIGN_OR_RETURN(pitch_as_written,
                          audio::ParsePitchCsv(audio::FormatPitchCsv(pitch.frames), pitch_path));
    stages.pitch = &pitch_as_written;
    ARCO_ASSIGN_OR_RETURN(stages.notes,
                          audio::ParseNotesCsv(audio::FormatNotesCsv(pitch.notes), pitch_path));
  }
  std::vector<audio::PolyPitchFrame> double_stops_as_written;
  if (!pitch.double_stops.empty()) {
    ARCO_ASSIGN_OR_RETURN(
        double_stops_as_written,
        audio::ParseDoubleStopsCsv(audio::FormatDoubleStopsCsv(pitch.double_stops), pitch_path));
  }
  ARCO_ASSIGN_OR_RETURN(RefineInputs inputs, MakeRefineInputs(options.result_dir, stages));
  // arco's bow arm, once for the double stops' bow gate and arco's bowing.csv.
  if (inputs.has_pitch) ARCO_RETURN_IF_ERROR(AnalyzeBowArm(refine::BowingOptions(), &inputs));
  if (!double_stops_as_written.empty()) {
    AddDoubleStops(double_stops_as_written, &inputs, refine::DoubleStopRefineOptions().bow_pairs);
  }
  std::vector<refine::RefineMode> modes = {refine::RefineMode::kVision};
  if (inputs.has_pitch) {
    modes.push_back(refine::RefineMode::kPaper);
    modes.push_back(refine::RefineMode::kArco);
  }
  progress.SetTotal(static_cast<int64_t>(modes.size()));
  std::vector<MethodRecord> methods;
  methods.reserve(modes.size());  // `made`'s records stay where they are (and when moved)
  for (refine::RefineMode mode : modes) {
    const RefineStageOptions ro = options.ForRefine(mode);
    ARCO_ASSIGN_OR_RETURN(MethodRecord method, RefineMethod(inputs, ro.refine));
    methods.push_back(std::move(method));
    if (made) made(methods.back());
    progress.Advance(1);
  }
  return methods;
}

Status WriteRunRecords(const ResultFolder& result,
                       const CaptureContext& capture,
                       RunRecords* records) {
  ARCO_RETURN_IF_ERROR(WriteTriangulation(result, capture, &records->triangulation));
  ARCO_RETURN_IF_ERROR(result.WriteInstrument(records->instrument));
  ARCO_RETURN_IF_ERROR(result.WriteHand(records->hand));
  if (records->pitch.summary.ran) ARCO_RETURN_IF_ERROR(result.WritePitch(records->pitch));
  for (const MethodRecord& method : records->methods) {
    ARCO_RETURN_IF_ERROR(result.WriteMethod(method));
  }
  return Status::Ok();
}

Status WriteRunResult(const Validated<RunOptions>& options,
                      const CaptureContext& capture,
                      RunRecords records) {
  ARCO_RETURN_IF_ERROR(CheckOutputFolder(options->result_dir, options->Replace()));
  return WriteResultFolder(*options, [&](const RunOptions&, const ResultFolder& result) {
    return WriteRunRecords(result, capture, &records);
  });
}

StatusOr<CaptureContext> OpenRunCapture(const Validated<RunOptions>& options) {
  ARCO_ASSIGN_OR_RETURN(CaptureContext capture, OpenCapture(options->capture_dir));
  return PreflightOpened(*options, std::move(capture));
}

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
