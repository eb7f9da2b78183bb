// `arco synth`: a synthetic performance with exact truth (docs/synth.md).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "arco/calibration/calibration_file.h"
#include "arco/cli/command.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/synth/capture_writer.h"
#include "arco/synth/error_model.h"
#include "arco/synth/motion.h"
#include "arco/synth/synth.h"

#ifndef ARCO_SHARED_DATA_DIR
#define ARCO_SHARED_DATA_DIR ""
#endif

namespace arco::cli {
namespace {

namespace fs = std::filesystem;
constexpr char kDefaultRig[] = "spd/cello_1113_scale_camera.xml";

// The SPD rig: $ARCO_SHARED_DATA_DIR, then the data folder this binary was built
// with, then ../shared/data next to the repository that holds the binary
// (REPO/build/bin/arco), then ../shared/data from the working directory.
std::string DefaultCalibration() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("ARCO_SHARED_DATA_DIR"))
    candidates.emplace_back(fs::path(env) / kDefaultRig);
  if (*ARCO_SHARED_DATA_DIR) candidates.emplace_back(fs::path(ARCO_SHARED_DATA_DIR) / kDefaultRig);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path p = exe.parent_path(); !p.empty() && p != p.root_path(); p = p.parent_path()) {
      candidates.emplace_back(p / ".." / "shared" / "data" / kDefaultRig);
    }
  }
  candidates.emplace_back(fs::path("..") / "shared" / "data" / kDefaultRig);
  for (const fs::path& c : candidates) {
    if (fs::exists(c, ec)) return fs::weakly_canonical(c, ec).string();
  }
  return (fs::path("..") / "shared" / "data" / kDefaultRig).string();
}

struct Args {
  synth::SynthOptions o;
  synth::WriteOptions w;
  std::string calibration, output;
  bool no_audio = false, no_sample_tuning = false, no_vibrato = false,
       no_geometric_occlusion = false;
  bool list_pieces = false;
  // Re-capture of a recorded take (synth/motion.h).
  std::string motion, audio, error_model = "synth", cameras;
  bool list_error_models = false;
  // The detection flags, to tell the ones given (they override the error model's preset).
  std::vector<std::pair<CLI::Option*, double synth::DetectionOptions::*>> detection_flags;
};

// The summary's last line. "cap/" and "cap" name the same folder: printed once, without
// the slash.
void PrintWritten(std::string folder, int64_t bytes, double total_s) {
  while (folder.size() > 1 && folder.back() == '/') folder.pop_back();
  std::printf("  wrote         %s/ (%.1f MB) and %s/truth/ in %.1f s\n",
              folder.c_str(),
              bytes / 1e6,
              folder.c_str(),
              total_s);
}

// The error model's preset with the detection flags the user gave applied over it.
StatusOr<synth::DetectionOptions> DetectionFor(const Args& a) {
  ARCO_ASSIGN_OR_RETURN(synth::DetectionOptions o, synth::ErrorModelOptions(a.error_model));
  for (const auto& [option, field] : a.detection_flags)
    if (option->count() > 0) o.*field = a.o.detection.*field;
  if (a.no_geometric_occlusion) o.geometric_occlusion = false;
  return o;
}

// `arco synth --motion`: a recorded take re-captured in the rig.
int RunMotion(Args& a) {
  synth::MotionOptions m;
  m.motion_path = a.motion;
  m.audio_path = a.audio;
  m.instrument = a.o.instrument;
  m.fps = a.o.fps;
  m.max_duration_s = a.o.max_duration_s;
  m.a4_hz = a.o.a4_hz;
  m.seed = a.o.seed;
  m.num_threads = a.o.num_threads;
  m.stage = a.o.stage;
  m.error_model = a.error_model;
  m.cameras = a.cameras;
  auto detection = DetectionFor(a);
  if (!detection.ok()) return PrintError("--error-model: " + detection.status().message());
  m.detection = *detection;
  const Status valid = m.Validate();
  if (!valid.ok()) return PrintError(WithFlagNames(valid.message(), kSynthFlags));
  const Status writable = synth::CheckCaptureOutput(a.output, a.w);
  if (!writable.ok()) return PrintError(writable.message());
  const auto start = std::chrono::steady_clock::now();
  auto calibration = calibration::LoadCalibration(a.calibration);
  if (!calibration.ok()) return PrintError(calibration.status().message());
  auto capture = synth::GenerateFromMotion(calibration->rig, m);
  if (!capture.ok()) {
    const std::string msg = capture.status().message();
    // Messages about the motion or the audio name their file; the rest is the rig's.
    const bool named = msg.rfind(a.motion, 0) == 0 || msg.rfind(a.audio, 0) == 0;
    return PrintError(named ? msg : a.calibration + ": " + msg);
  }
  synth::WriteSummary ws;
  const Status written = synth::WriteCapture(*capture, a.output, a.w, &ws);
  if (!written.ok()) return PrintError(WithFlagNames(written.message(), kSynthFlags));
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& c = *capture;
  std::printf("arco synth: %s re-captured, error model %s, seed %llu\n",
              a.motion.c_str(),
              a.error_model.c_str(),
              static_cast<unsigned long long>(c.options.seed));
  std::printf("  calibration   %s (%zu cameras, %.1f mm per unit)\n",
              a.calibration.c_str(),
              c.rig_mm.cameras.size(),
              c.stage.mm_per_unit);
  std::printf("  motion        %d frames at %g fps (%.2f s), %d with a pressed note\n",
              c.num_frames,
              c.options.fps,
              c.num_frames / c.options.fps,
              c.pressed_frames);
  PrintWritten(a.output, ws.bytes, total_s);
  return 0;
}

int Run(Args& a) {
  if (a.list_pieces) {
    for (const auto& name : synth::BuiltInPieceNames()) {
      std::printf("%-14s %s\n", name.c_str(), synth::DescribeBuiltInPiece(name).c_str());
    }
    return 0;
  }
  if (a.list_error_models) {
    for (const auto& m : synth::ErrorModels())
      std::printf("%-10s %s\n", m.name.c_str(), m.description.c_str());
    return 0;
  }
  if (a.output.empty()) return PrintError("synth: -o OUT_DIR is required");
  if (a.calibration.empty()) a.calibration = DefaultCalibration();
  if (!a.cameras.empty() && a.motion.empty()) return PrintError("synth: --cameras needs --motion");
  if (!a.motion.empty() || !a.audio.empty()) {
    if (a.motion.empty()) return PrintError("synth: --audio needs --motion");
    if (a.audio.empty()) return PrintError("synth: --motion needs --audio (the take's recording)");
    a.w.calibration_source = a.calibration;
    return RunMotion(a);
  }
  {
    auto detection = DetectionFor(a);
    if (!detection.ok()) return PrintError("--error-model: " + detection.status().message());
    a.o.detection = *detection;
  }
  a.o.expression.vibrato = !a.no_vibrato;
  a.w.audio = !a.no_audio;
  a.w.audio_render.tune_soundfont = !a.no_sample_tuning;
  a.w.calibration_source = a.calibration;
  // The options are the user's flags, not the calibration's: checked first, named as flags.
  const Status valid = a.o.Validate();
  if (!valid.ok()) return PrintError(WithFlagNames(valid.message(), kSynthFlags));
  // The output is checked before the work (docs/architecture.md, "Outputs").
  const Status writable = synth::CheckCaptureOutput(a.output, a.w);
  if (!writable.ok()) return PrintError(writable.message());
  const auto start = std::chrono::steady_clock::now();
  auto calibration = calibration::LoadCalibration(a.calibration);
  if (!calibration.ok()) return PrintError(calibration.status().message());
  auto capture = synth::Generate(calibration->rig, a.o);
  if (!capture.ok()) {
    const std::string where = a.o.midi_path.empty() ? a.calibration : a.o.midi_path;
    const std::string msg = capture.status().message();
    // Messages from the MIDI reader already name the file.
    return PrintError(msg.rfind(where, 0) == 0 ? msg : where + ": " + msg);
  }
  const double generate_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr,
               "synth: generated %d frames in %.1f s; writing %s\n",
               capture->num_frames,
               generate_s,
               a.output.c_str());
  synth::WriteSummary ws;
  const Status written = synth::WriteCapture(*capture, a.output, a.w, &ws);
  if (!written.ok()) return PrintError(WithFlagNames(written.message(), kSynthFlags));
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& c = *capture;
  const auto& k = c.keypoints2d;
  int64_t detected = 0, confident = 0;
  for (int64_t i = 0; i < k.size() / 3; ++i) {
    detected += !std::isnan(k.data[static_cast<size_t>(3 * i)]);
    confident += k.data[static_cast<size_t>(3 * i + 2)] >= 0.5f;
  }
  const int64_t slots = k.size() / 3;
  std::printf("arco synth: %s, %s, seed %llu\n",
              c.options.instrument.c_str(),
              c.options.midi_path.empty() ? c.options.piece.c_str() : c.options.midi_path.c_str(),
              static_cast<unsigned long long>(c.options.seed));
  std::printf("  calibration   %s (%zu cameras, %.1f mm per unit)\n",
              a.calibration.c_str(),
              c.rig_mm.cameras.size(),
              c.stage.mm_per_unit);
  std::printf("  performance   %zu notes, %.2f s, %d frames at %g fps, %d with a pressed note\n",
              c.performance.notes.size(),
              c.num_frames / c.options.fps,
              c.num_frames,
              c.options.fps,
              c.pressed_frames);
  std::printf("  fingering     %d shifts, %d open strings, %d string crossings\n",
              c.fingering.num_shifts,
              c.fingering.num_open_strings,
              c.fingering.num_string_crossings);
  std::printf(
      "  left hand     largest whole-hand correction %.1f mm (fingertips exact on the strings)\n",
      c.max_residual_shift_mm);
  if (c.double_stops > 0) {
    std::printf("  double stops  %d, both fingertips within %.1f mm of their contacts\n",
                c.double_stops,
                c.max_second_residual_mm);
  }
  std::printf("  detections    %.1f%% of keypoint slots in view, %.1f%% with score >= 0.5\n",
              100.0 * detected / std::max<int64_t>(1, slots),
              100.0 * confident / std::max<int64_t>(1, slots));
  if (a.w.audio) {
    double worst = 0;
    for (const auto& [key, cents] : ws.audio.key_offset_cents)
      worst = std::max(worst, std::abs(cents));
    std::printf(
        "  audio         audio.wav (%zu keys measured, sample detuning up to %.1f cents, "
        "compensated)\n",
        ws.audio.key_offset_cents.size(),
        worst);
  }
  PrintWritten(a.output, ws.bytes, total_s);
  return 0;
}

CommandRun SetupSynth(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "synth", "Synthesise a string performance with exact truth (docs/synth.md)");
  auto a = std::make_shared<Args>();
  cmd->add_option("-o,--output", a->output, "Output capture folder (truth/ goes inside)");
  cmd->add_option("--instrument", a->o.instrument, "cello, violin, viola or double_bass")
      ->capture_default_str();
  cmd->add_option("--piece", a->o.piece, "Built-in piece (see --list-pieces)")
      ->capture_default_str();
  cmd->add_flag("--list-pieces", a->list_pieces, "List the built-in pieces and exit");
  cmd->add_option("--midi",
                  a->o.midi_path,
                  "Standard MIDI File to play instead of a piece (one note at a time)");
  cmd->add_option("--calibration",
                  a->calibration,
                  "Camera calibration (any format arco reads); default: the SPD rig " +
                      std::string(kDefaultRig) +
                      " found via $ARCO_SHARED_DATA_DIR or ../shared/data");
  AddNumber(cmd,
            "--seed",
            a->o.seed,
            "Random seed (same seed, same capture)",
            Closed(0, kMaxExactInteger))
      ->capture_default_str();
  AddNumber(cmd, "--fps", a->o.fps, "Video frame rate (Hz)", Closed(1, kVideoFpsRange.max))
      ->capture_default_str();
  AddNumber(cmd,
            "--duration-s",
            a->o.max_duration_s,
            "Keep only the first seconds of the piece (0 = all)",
            Closed(0, 86400))
      ->capture_default_str();
  AddNumber(cmd,
            "--tempo-scale",
            a->o.tempo_scale,
            "Stretch all durations (> 1 plays slower)",
            NumberRange{0.05, 20, true, true})
      ->capture_default_str();
  AddNumber(cmd, "--a4", a->o.a4_hz, "Concert pitch A4 (Hz)", kA4RangeHz)->capture_default_str();
  AddNumber(cmd,
            "--intonation-cents",
            a->o.expression.intonation_sigma_cents,
            "Std. dev. of per-note intonation error (cents, clipped to +-15)",
            Closed(0, 100))
      ->capture_default_str();
  cmd->add_flag("--no-vibrato", a->no_vibrato, "Play every note straight");
  AddNumber(cmd,
            "--vibrato-max-cents",
            a->o.expression.vibrato_extent_max_cents,
            "Largest vibrato extent (half peak-to-peak, cents; at least the smallest drawn "
            "extent, 12; --no-vibrato for none)",
            Closed(12, 100))
      ->capture_default_str();
  a->detection_flags.emplace_back(AddNumber(cmd,
                                            "--noise-px",
                                            a->o.detection.noise_px,
                                            "2D detection noise per axis (px)",
                                            NumberRange{0, 200, false, true})
                                      ->capture_default_str(),
                                  &synth::DetectionOptions::noise_px);
  a->detection_flags.emplace_back(
      AddNumber(cmd,
                "--outlier-rate",
                a->o.detection.outlier_rate,
                "Gross outliers per keypoint, and hand swaps per view and frame (fraction)",
                kFractionRange)
          ->capture_default_str(),
      &synth::DetectionOptions::outlier_rate);
  a->detection_flags.emplace_back(
      AddNumber(cmd,
                "--occlusion-rate",
                a->o.detection.occlusion_rate,
                "Random detector drop-outs per keypoint (fraction), on top of geometric occlusion",
                kFractionRange)
          ->capture_default_str(),
      &synth::DetectionOptions::occlusion_rate);
  cmd->add_flag("--no-geometric-occlusion",
                a->no_geometric_occlusion,
                "Do not occlude points hidden by the instrument body or the torso");
  a->detection_flags.emplace_back(AddNumber(cmd,
                                            "--finger-bias-mm",
                                            a->o.detection.finger_bias_mm,
                                            "3D offset of the playing fingertip off the string as "
                                            "the detector sees it (mm; DIP half)",
                                            NumberRange{0, 200, false, true})
                                      ->capture_default_str(),
                                  &synth::DetectionOptions::finger_bias_mm);
  a->detection_flags.emplace_back(
      AddNumber(cmd,
                "--jitter-mm",
                a->o.detection.jitter_mm,
                "View-consistent 3D detector error per axis for hand points (mm; body x1.5, "
                "instrument x0.3)",
                NumberRange{0, 100, false, true})
          ->capture_default_str(),
      &synth::DetectionOptions::jitter_mm);
  AddNumber(cmd,
            "--mm-per-unit",
            a->o.stage.mm_per_unit,
            "Millimetres per calibration unit (0 = automatic: from the units, else the SPD "
            "rig's camera distance)",
            Closed(0, 1e6))
      ->capture_default_str();
  a->detection_flags.emplace_back(
      AddNumber(cmd,
                "--finger-offset-mm",
                a->o.detection.finger_offset_mm,
                "Smooth per-finger 3D offset of the left hand shared by all views, at the tip "
                "(mm per axis; error models shared, harsh)",
                NumberRange{0, 100, false, true}),
      &synth::DetectionOptions::finger_offset_mm);
  a->detection_flags.emplace_back(
      AddNumber(cmd,
                "--hand-back-deg",
                a->o.detection.hand_back_max_deg,
                "Hide the left fingers in views within this angle of the back of the hand "
                "(degrees, 0 = off; error models behind, harsh)",
                Closed(0, 90)),
      &synth::DetectionOptions::hand_back_max_deg);
  a->detection_flags.emplace_back(
      AddNumber(cmd,
                "--finger-confusion-rate",
                a->o.detection.finger_confusion_rate,
                "Neighbouring left fingers swapped per view and frame (fraction; error models "
                "confusion, harsh)",
                kFractionRange),
      &synth::DetectionOptions::finger_confusion_rate);
  cmd->add_option("--error-model",
                  a->error_model,
                  "Detector error model (see --list-error-models); the detection flags given "
                  "override its values")
      ->capture_default_str();
  cmd->add_flag(
      "--list-error-models", a->list_error_models, "List the detector error models and exit");
  cmd->add_option("--motion",
                  a->motion,
                  "Re-capture a recorded take: released 3D results (frames, points, 3) in mm in "
                  "the instrument's spd_*_contact layout (docs/synth.md)");
  cmd->add_option("--audio", a->audio, "The recorded take's audio (with --motion), frame 0 at 0 s");
  cmd->add_option("--cameras",
                  a->cameras,
                  "With --motion: the cameras that film the take, a count (spread around the "
                  "performer) or names separated by commas (default: all)");
  cmd->add_flag("--no-audio", a->no_audio, "Skip rendering audio.wav");
  cmd->add_option("--soundfont", a->w.audio_render.soundfont, "SoundFont for fluidsynth")
      ->capture_default_str();
  cmd->add_flag("--no-sample-tuning",
                a->no_sample_tuning,
                "Do not measure and compensate the soundfont samples' own pitch");
  AddNumber(cmd,
            "--room-noise-dbfs",
            a->w.audio_render.room_noise_dbfs,
            "Room noise RMS level (dBFS, e.g. -50; 0 = none)",
            NumberRange{-200, 0, true, false})
      ->capture_default_str();
  AddNumber(cmd,
            "--threads",
            a->o.num_threads,
            "Worker threads (0 = all cores; results do not depend on it)",
            kThreadsRange)
      ->capture_default_str();
  cmd->add_flag("--overwrite", a->w.overwrite, "Replace an existing output folder");
  cmd->parse_complete_callback([a] {
    const Status valid = a->o.Validate();  // combinations the ranges above cannot see
    if (!valid.ok()) ThrowIfInvalid(Status::Error(WithFlagNames(valid.message(), kSynthFlags)));
  });
  return CommandRun([a] { return Run(*a); },
                    [a] {
                      PathRoles roles;
                      roles.AddInput(
                          "--calibration",
                          a->calibration.empty() ? DefaultCalibration() : a->calibration);
                      roles.AddInput("--midi", a->o.midi_path);
                      roles.AddInput("--motion", a->motion);
                      roles.AddInput("--audio", a->audio);
                      if (!a->no_audio && a->motion.empty())
                        roles.AddInput("--soundfont", a->w.audio_render.soundfont);
                      roles.AddOutput("-o", a->output);
                      return roles;
                    });
}

}  // namespace
ARCO_REGISTER_COMMAND(synth, 60, SetupSynth);
}  // namespace arco::cli
