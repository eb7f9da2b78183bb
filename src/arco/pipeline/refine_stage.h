// Stage 5: the audio-guided refinement (refine/refine.h) of one method, read from and
// written to a result folder: RESULT_DIR/<method>/ (pipeline/result_folder.h). `arco run`
// writes vision, paper and arco; `arco refine` re-runs one method from the files of
// stages 1-4, so both refine exactly the same data.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "arco/audio/double_stops.h"
#include "arco/instrument/instrument_model.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/bowing.h"
#include "arco/refine/double_stop_refine.h"
#include "arco/refine/method_result.h"
#include "arco/refine/refine.h"
#include "arco/util/status.h"
#include "arco/util/validated.h"

namespace arco::pipeline {

struct RefineStageOptions {
  std::string result_dir;        // written by stages 1-4
  refine::RefineOptions refine;  // refine.mode picks the method
  refine::BowingOptions bowing;  // arco's bow arm (arco/bowing.csv)
  Status Validate() const;
};

// Everything the refinement needs, read from a result folder.
struct RefineInputs {
  std::shared_ptr<const InstrumentModel> instrument;
  refine::RefineInput input;  // input.pitch all unvoiced when the result has no pitch stage
  refine::SpdSources spd;
  bool has_pitch = false;
  // Double stops (refine/double_stop_refine.h; `arco run --double-stops`): the upper note
  // per frame (0 = none), input.pitch then holding the lower one on those frames (see
  // AddDoubleStops). Empty: off, and arco writes no contacts_2.csv.
  std::vector<double> upper_f0_hz;
  // Frames whose two notes AddDoubleStops took from the pair heard on the strings the bow
  // rests on (DoubleStopRefineSummary::bow_pairs).
  int bow_pair_frames = 0;
  // arco's bow arm (refine/bowing.h: strokes, without notes), analysed once by
  // AnalyzeBowArm with bowing_options: AddDoubleStops' bow gate and arco's bowing.csv read
  // it. Empty until then (vision and paper need none).
  std::optional<refine::BowingResult> bow;
  refine::BowingOptions bowing_options;
};

// Analyses the bow arm from the triangulated frog and tip and the placed strings
// (refine::AnalyzeBowStrokes) into inputs->bow, with these options. Errors: the
// instrument's layout has no frog and tip.
Status AnalyzeBowArm(const refine::BowingOptions& options, RefineInputs* inputs);

// Puts a polyphonic tracker's two notes (audio/double_stops.h, one frame per video frame;
// the pitch stage's double_stops.csv, read back by LoadRefineInputs) into the inputs: on
// each frame with two notes, the lower becomes the frame's pitch (confidence 1: both notes
// were found) and the upper goes to upper_f0_hz. With bow_pairs and inputs->bow
// (AnalyzeBowArm), a frame whose bow rests on two adjacent strings s and s + 1
// (refine::BowRestOf) takes the pair the tracker heard as played on those strings
// (PolyPitchFrame::on_strings), where it heard one, whatever the free analysis found, and
// input.bowed_pair_lower_string the pair's lower string (the first voice's): the bow says
// which strings sound, the free analysis often hears a pair's partial or a ghost an octave
// away as one of its notes (docs/accuracy.md, "Double stops"); a frame whose bow clearly
// rests on one string keeps the single-note tracker's reading unless it is the free pair's
// lower note (VoicesOfFrame). Throws std::invalid_argument when the frame counts differ.
void AddDoubleStops(const std::vector<audio::PolyPitchFrame>& poly,
                    RefineInputs* inputs,
                    bool bow_pairs = true);

// One frame of AddDoubleStops: the voices from the polyphonic frame, the single-note
// tracker's reading `heard` and where the bow rests (refine::BowRestOf; a default BowRest
// when unknown). On two strings: their pair (on_strings), except a lone octave. Otherwise,
// two notes from the free analysis: the lower is the first voice (confidence 1) and the
// upper the second, except with the bow clearly on one string (within kOneStringRestDeg of
// its inclination) where the tracker does not hear the lower note: `heard` stays, alone.
struct FrameVoices {
  refine::FramePitch first;
  double upper_f0_hz = 0;           // 0: no second voice
  int bowed_pair_lower_string = 0;  // > 0: the pair came from the bowed strings
};
// A bow within this of one string's inclination rests on that string alone. The pair
// beside it is about 10 degrees away on every instrument's arch, but the measured
// inclination scatters by 0.8 (double bass) to 2.3 degrees (violin) sd on the synthetic
// takes, and a violin's double stop was measured 2.3 degrees from one string (2.5 lost it).
constexpr double kOneStringRestDeg = 1.5;
FrameVoices VoicesOfFrame(const audio::PolyPitchFrame& poly,
                          const refine::FramePitch& heard,
                          const refine::BowRest& rest);
// The pairs taken from the bowed strings, made consistent over time (after VoicesOfFrame,
// before the refinement): the tracker's search on two strings sometimes takes a ghost for
// one note of the pair (a viola chord's D3 + A3 on its C and G strings heard as F#3 + A3 on
// every other frame, F#3 the subharmonic of the F#4 still ringing), and the first voice
// then jumps so often that the pitch model drops the stretch. A frame's pair (its notes to
// the nearest semitone) bowed on strings s and s - 1 takes the pair found on more frames
// bowed on the same strings within window_frames of it, on both sides of it (so a change
// of notes under one bow is kept), from that pair's nearest frame (the earlier on a tie).
// Decisions are made on the input, so the order of frames plays no part. 0: unchanged.
// AddDoubleStops' window each side is the free pairs' (audio::DoubleStopOptions'
// default consistency_s, rounded to frames at the video's fps).
void ConsistentBowedPairs(int window_frames, std::vector<FrameVoices>* voices);
// Errors name the file: no hand or instrument stage, shapes that disagree, a
// double_stops.csv with more rows than frames. With a pitch stage, AnalyzeBowArm (with
// `bowing`); with double_stops.csv, AddDoubleStops.
StatusOr<RefineInputs> LoadRefineInputs(const std::string& result_dir,
                                        const refine::BowingOptions& bowing = {});

// What the refinement reads of stages 1-4, as their files hold it: `arco run` passes
// the records it made (hands, pitch and notes through their files' encodings, in
// memory), LoadRefineInputs the records it read, so both refine the same data.
struct StageRecords {
  double fps = 30;                                      // the capture's (result.json "fps")
  const NpyArray<double>* points3d_in_world = nullptr;  // triangulation/points3d.npy
  const InstrumentRecord* instrument = nullptr;
  const HandRecord* hand = nullptr;
  const std::vector<audio::PitchFrame>* pitch = nullptr;  // null: no pitch stage
  std::vector<audio::Note> notes;                         // notes.csv's notes
  // One camera: its centre (world units; TriangulationRecord::one_view_camera_centre).
  std::optional<Eigen::Vector3d> one_view_camera_centre_in_world;
  // The instrument's model when already built (the run's CaptureContext); null: built
  // from the instrument record (its name and A4).
  std::shared_ptr<const InstrumentModel> model;
};
// `result_dir` names the files in messages (shapes that disagree).
StatusOr<RefineInputs> MakeRefineInputs(const std::string& result_dir, const StageRecords& records);

// Refines one method (options.mode); arco's also gets the bow arm (inputs.bow with the
// final notes, refine/bowing.h: bowing.csv, bowing_notes.csv; arco without inputs.bow is
// a caller bug, std::invalid_argument). Writes nothing: the record is what
// ResultFolder::WriteMethod writes into RESULT_DIR/<method>/ (record.summary: the method's
// summary). A method that needs audio on inputs without pitch is a caller bug
// (std::invalid_argument): RefineAndWrite checks it first. Precondition: the options are
// valid (RefineStageOptions::Validate: RunCapture and RunRefineStage check them once at
// their entry); not checked here.
StatusOr<MethodRecord> RefineMethod(const RefineInputs& inputs,
                                    const refine::RefineOptions& options);
// RefineMethod into the result folder `result_dir`. Errors: a method that needs audio on
// a result without a pitch stage.
StatusOr<refine::RefineSummary> RefineAndWrite(const std::string& result_dir,
                                               const RefineInputs& inputs,
                                               const refine::RefineOptions& options);

// `arco refine`: the options validated once, here at the entry, then LoadRefineInputs +
// RefineAndWrite.
StatusOr<refine::RefineSummary> RunRefineStage(const RefineStageOptions& options);
// The same with options already validated (`arco refine` checks them when it parses its
// command line).
StatusOr<refine::RefineSummary> RunRefineStage(const Validated<RefineStageOptions>& options);

}  // namespace arco::pipeline
