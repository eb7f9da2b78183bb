#include "arco/capture/detect_stage.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <utility>

#include "arco/calibration/calibration_file.h"
#include "arco/camera/rig.h"
#include "arco/capture/capture_videos.h"
#include "arco/media/video_reader.h"
#include "arco/mocap/capture.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"
#include "arco/util/output_set.h"
#include "arco/util/parallel.h"

namespace arco::capture {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr char kKeypointsFile[] = "keypoints2d.npy";
constexpr char kReportFile[] = "detect.json";

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One work item: frames [first, last] (global numbers) of one camera.
struct Chunk {
  int view = 0;
  int64_t first = 0, last = 0;
};

// Per-worker state: its tracker and the videos it has open.
struct Worker {
  std::optional<detect::WholeBodyTracker> tracker;
  std::map<int, CaptureFrameReader> readers;
  double decode_s = 0;       // reading and decoding frames (on the decoding thread)
  double decode_wait_s = 0;  // the tracker waiting for its next frame
};

Json SummaryJson(const detect::WholeBodySummary& s) {
  Json models = Json::array();
  for (const auto& m : s.models) {
    if (m.runs == 0) continue;
    models.push_back({{"model", GetModelInfo(m.model).name},
                      {"runtime", m.runtime},
                      {"runs", m.runs},
                      {"inference_ms_per_run", 1e3 * m.inference_s / m.runs}});
  }
  return Json{{"frames", s.frames},
              {"frames_with_person", s.frames_with_person},
              {"frames_with_left_hand", s.frames_with_left_hand},
              {"frames_with_right_hand", s.frames_with_right_hand},
              {"detector_runs", s.detector_runs},
              {"redetections", s.redetections},
              {"hands_tracked", s.hands_tracked},
              {"hands_reused", s.hands_reused},
              {"models", models},
              {"inference_s", s.inference_s},
              {"preprocess_s", s.preprocess_s},
              {"postprocess_s", s.postprocess_s}};
}

// after - before: one chunk's counts and times from a worker's running totals.
detect::WholeBodySummary Difference(const detect::WholeBodySummary& after,
                                    const detect::WholeBodySummary& before) {
  detect::WholeBodySummary d = after;
  d.frames -= before.frames;
  d.frames_with_person -= before.frames_with_person;
  d.frames_with_left_hand -= before.frames_with_left_hand;
  d.frames_with_right_hand -= before.frames_with_right_hand;
  d.detector_runs -= before.detector_runs;
  d.redetections -= before.redetections;
  d.hands_tracked -= before.hands_tracked;
  d.hands_reused -= before.hands_reused;
  for (size_t k = 0; k < d.models.size(); ++k) {
    d.models[k].runs -= before.models[k].runs;
    d.models[k].inference_s -= before.models[k].inference_s;
  }
  d.inference_s -= before.inference_s;
  d.preprocess_s -= before.preprocess_s;
  d.postprocess_s -= before.postprocess_s;
  return d;
}

}  // namespace

Status DetectStageOptions::Validate() const {
  if (capture_dir.empty()) return Status::Error("capture_dir is empty");
  detect::WholeBodyOptions d = detector;
  d.num_threads = 1;  // the stage's own
  ARCO_RETURN_IF_ERROR(d.Validate().WithContext("detector"));
  ARCO_RETURN_IF_ERROR(CheckInRange("num_threads", num_threads, Closed(0, 1024)));
  ARCO_RETURN_IF_ERROR(CheckInRange("chunk_frames", chunk_frames, kDetectChunkFramesRange));
  ARCO_RETURN_IF_ERROR(hands.Validate().WithContext("hands"));
  if (first_frame < -1) return Status::Error("first_frame must be -1 (the first) or >= 0");
  if (last_frame < -1) return Status::Error("last_frame must be -1 (the last) or >= 0");
  if (first_frame >= 0 && last_frame >= 0 && last_frame < first_frame) {
    return Status::Error("last_frame " + std::to_string(last_frame) + " is before first_frame " +
                         std::to_string(first_frame));
  }
  return Status::Ok();
}

Json ToJson(const DetectStageOptions& o) {
  return Json{{"pose_model", detect::PoseModelName(o.detector.pose_model)},
              {"hand_model", detect::HandModelName(o.detector.hand_model)},
              {"inference", detect::InferenceRuntimeName(o.detector.runtime)},
              {"min_detection_score", o.detector.min_detection_score},
              {"nms_min_iou", o.detector.nms_min_iou},
              {"min_pose_presence", o.detector.min_pose_presence},
              {"min_hand_presence", o.detector.min_hand_presence},
              {"hand_recrop", o.detector.hand_recrop},
              {"hand_tracking", o.detector.hand_tracking},
              {"min_hand_tracking_presence", o.detector.min_hand_tracking_presence},
              {"hand_reuse_max_change", o.detector.hand_reuse_max_change},
              {"detection_tile_levels", o.detector.detection_tile_levels},
              {"chunk_frames", o.chunk_frames},
              {"hands", ToJson(o.hands)},
              {"first_frame", o.first_frame},
              {"last_frame", o.last_frame}};
}

Json ToJson(const DetectStageSummary& s) {
  Json cameras = Json::array();
  for (const auto& c : s.cameras) {
    Json j = SummaryJson(c.tracker);
    j["camera"] = c.camera;
    j["video"] = c.video;
    j["frames_read"] = c.frames;
    j["dropped"] = c.dropped;
    cameras.push_back(std::move(j));
  }
  return Json{{"layout", s.layout},
              {"first_frame", s.first_frame},
              {"last_frame", s.last_frame},
              {"points", s.points},
              {"kept_other_points", s.kept_other_points},
              {"hands", ToJson(s.hands)},
              {"total", SummaryJson(s.total)},
              {"cameras", cameras},
              {"decode_s", s.decode_s},
              {"decode_wait_s", s.decode_wait_s},
              {"wall_s", s.wall_s}};
}

StatusOr<DetectStageSummary> RunDetectStage(const DetectStageOptions& options, Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  ARCO_RETURN_IF_ERROR(options.Validate());
  const std::string& dir = options.capture_dir;
  const std::string manifest_path = CaptureManifestPath(dir);
  ARCO_ASSIGN_OR_RETURN(CaptureManifest manifest, ReadCaptureManifest(dir));

  // --- Checks before any frame is decoded -------------------------------------------
  ARCO_ASSIGN_OR_RETURN(const std::string layout_name, DetectionLayoutName(manifest.instrument));
  const KeypointLayout* layout = FindKeypointLayout(layout_name);
  if (layout == nullptr) return Status::Error(manifest_path + ": no layout " + layout_name);
  const int64_t points = static_cast<int64_t>(layout->names.size());
  if (manifest.frame_count <= 0) return Status::Error(manifest_path + ": frames.count is 0");
  const int64_t capture_first = manifest.frame_first;
  const int64_t capture_last = manifest.frame_first + manifest.frame_count - 1;
  const int64_t first = options.first_frame >= 0 ? options.first_frame : capture_first;
  const int64_t last = options.last_frame >= 0 ? options.last_frame : capture_last;
  if (first < capture_first || last > capture_last || last < first) {
    return Status::Error("frames " + std::to_string(first) + ":" + std::to_string(last) +
                         " are outside the capture's frames " + std::to_string(capture_first) +
                         ":" + std::to_string(capture_last) + " (" + manifest_path + ")");
  }

  ARCO_ASSIGN_OR_RETURN(const std::vector<CaptureVideo> inputs,
                        OpenCaptureVideos(dir, manifest, first, last));
  const int views = static_cast<int>(inputs.size());

  // Keypoints already in the capture: the slots after the body and hands (instrument and
  // bow, from `arco track`) and the frames outside [first, last] are kept.
  NpyArray<float> out;
  out.shape = {manifest.frame_count, views, points, 3};
  out.data.assign(static_cast<size_t>(manifest.frame_count * views * points * 3), kNaN);
  bool kept = false;
  if (!manifest.keypoints2d.empty() && manifest.layout == layout_name) {
    ARCO_RETURN_IF_ERROR(CheckCaptureKeypoints2d(dir, manifest));
    // Each camera's own frames: rewritten as they are.
    ARCO_ASSIGN_OR_RETURN(NpyArray<double> old,
                          ReadCaptureKeypoints2d(dir, manifest, KeypointTimes::kAsRecorded));
    for (size_t i = 0; i < out.data.size(); ++i) out.data[i] = static_cast<float>(old.data[i]);
    kept = true;
  }
  const auto at = [&](int64_t f, int v, int64_t p) {
    return static_cast<size_t>(((f * views + v) * points + p) * 3);
  };
  // The body and hand slots of the detected range start empty.
  for (int64_t g = first; g <= last; ++g)
    for (int v = 0; v < views; ++v)
      for (int64_t p = 0; p < wholebody::kNumPoints; ++p) {
        const size_t k = at(g - capture_first, v, p);
        out.data[k] = out.data[k + 1] = out.data[k + 2] = kNaN;
      }

  // Outputs declared (and their locations checked) before the work.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string npy_tmp, outputs.AddFile(JoinPath(dir, kKeypointsFile)));
  ARCO_ASSIGN_OR_RETURN(const std::string manifest_tmp, outputs.AddFile(manifest_path));
  ARCO_ASSIGN_OR_RETURN(const std::string report_tmp, outputs.AddFile(JoinPath(dir, kReportFile)));

  // The models load here (a missing file is one line naming it).
  const int threads = ResolveThreadCount(options.num_threads);
  std::vector<Chunk> chunks;
  for (int v = 0; v < views; ++v)
    for (int64_t f = first; f <= last; f += options.chunk_frames)
      chunks.push_back({v, f, std::min<int64_t>(last, f + options.chunk_frames - 1)});
  const int workers = static_cast<int>(std::min<int64_t>(threads, chunks.size()));
  detect::WholeBodyOptions detector = options.detector;
  // cv::dnn's pool is process-wide: every tracker asks for the same size.
  detector.num_threads = std::max(1, threads / std::max(1, workers));
  std::vector<Worker> pool(workers);
  {
    ARCO_ASSIGN_OR_RETURN(detect::WholeBodyTracker first_tracker,
                          detect::WholeBodyTracker::Create(detector));
    pool[0].tracker.emplace(std::move(first_tracker));
  }

  // --- The work: (camera, chunk) items, each tracker restarted at its chunk ----------
  std::vector<detect::WholeBodySummary> chunk_summary(chunks.size());
  std::vector<int64_t> chunk_read(chunks.size(), 0), chunk_dropped(chunks.size(), 0);
  std::vector<Status> chunk_status(chunks.size(), Status::Ok());
  progress.SetTotal((last - first + 1) * views);
  ParallelFor(
      static_cast<int64_t>(chunks.size()),
      workers,
      [&](int64_t i, int t) {
        Worker& w = pool[t];
        const Chunk& c = chunks[i];
        const CaptureVideo& in = inputs[c.view];
        const auto fail = [&](Status s) { chunk_status[i] = std::move(s); };
        if (!w.tracker) {
          auto tracker = detect::WholeBodyTracker::Create(detector);
          if (!tracker.ok()) return fail(tracker.status());
          w.tracker.emplace(std::move(*tracker));
        }
        auto reader_it = w.readers.find(c.view);
        if (reader_it == w.readers.end()) {
          reader_it = w.readers.emplace(c.view, CaptureFrameReader(manifest, c.view, in)).first;
        }
        CaptureFrameReader& reader = reader_it->second;
        const detect::WholeBodySummary before = w.tracker->summary();
        w.tracker->Reset();
        // Decode ahead: frame g + 1 is read on its own thread while the tracker works on
        // frame g, so a worker's decoding overlaps its inference where a core is free
        // (docs/performance.md, "Issue 28, part 1: decoding ahead"). The tracker sees the
        // same frames in the same order, so the output does not change. Two buffers take
        // turns; the reader is used by one read at a time (each is waited for before the
        // next starts).
        struct Decoded {
          StatusOr<bool> read = false;
          double decode_s = 0;
        };
        std::array<media::Image, 2> frames;
        const auto decode = [&reader, &frames](int64_t g) {
          const auto decode_start = std::chrono::steady_clock::now();
          Decoded d;
          d.read = reader.Read(g, &frames[static_cast<size_t>(g % 2)]);
          d.decode_s = SecondsSince(decode_start);
          return d;
        };
        // Declared after `frames`, so an early return waits for the read before the
        // buffers go.
        std::future<Decoded> next = std::async(std::launch::deferred, decode, c.first);
        for (int64_t g = c.first; g <= c.last; ++g) {
          progress.Advance(1);
          const auto wait_start = std::chrono::steady_clock::now();
          Decoded d = next.get();
          w.decode_wait_s += SecondsSince(wait_start);
          if (!d.read.ok()) return fail(d.read.status());
          if (g < c.last) {
            next = std::async(
                options.decode_ahead ? std::launch::async : std::launch::deferred, decode, g + 1);
          }
          if (!*d.read) {
            ++chunk_dropped[i];
            continue;
          }
          w.decode_s += d.decode_s;
          auto found = w.tracker->Track(frames[static_cast<size_t>(g % 2)]);
          if (!found.ok()) return fail(found.status());
          ++chunk_read[i];
          for (int p = 0; p < wholebody::kNumPoints; ++p) {
            const detect::ScoredPoint& q = found->points[p];
            const size_t k = at(g - capture_first, c.view, p);
            out.data[k] = q.x_px;
            out.data[k + 1] = q.y_px;
            out.data[k + 2] = q.score;
          }
        }
        // This chunk's share of the worker's counts and times.
        const detect::WholeBodySummary delta = Difference(w.tracker->summary(), before);
        chunk_summary[i] = delta;
      },
      /*chunk=*/1);
  // The first failing item in item order (deterministic message).
  for (const Status& s : chunk_status) ARCO_RETURN_IF_ERROR(s);

  // --- Hands checked across the views (hand_consistency.h) ---------------------------
  HandConsistencySummary hands;
  const bool synced_by_sound =
      std::any_of(manifest.cameras.begin(), manifest.cameras.end(), [](const CaptureCamera& c) {
        return !c.OnCaptureClock();
      });
  if (!options.hands.enabled) {
    hands.skipped = "turned off";
  } else if (views < options.hands.min_views) {
    hands.skipped = "fewer cameras than hands.min_views";
  } else if (synced_by_sound) {
    hands.skipped = "cameras synced by sound: a row's views are not simultaneous";
  } else {
    const auto hands_start = std::chrono::steady_clock::now();
    hands.ran = true;
    Rig rig;
    for (const CaptureVideo& in : inputs) rig.cameras.push_back(in.calibration);
    const Triangulator triangulator(rig, ConsensusTriangulationOptions(options.hands));
    const int64_t n = last - first + 1;
    const auto frame_data = [&](int64_t g) { return &out.data[at(g - capture_first, 0, 0)]; };
    // Frames are independent: any split gives the same result.
    std::vector<FrameHandCheck> checks(static_cast<size_t>(n));
    ParallelFor(n, threads, [&](int64_t i, int) {
      checks[i] =
          CheckFrameHands(options.hands, triangulator, frame_data(first + i), views, points * 3);
    });
    // Disagreeing hands, by (view, frame, hand): each worker reads its frames in order.
    struct Rerun {
      int view = 0;
      int64_t frame = 0;
      int hand = 0;
      detect::Roi roi;
      std::array<detect::ScoredPoint, kHandPoints> points;
      double presence = 0;
      Status status = Status::Ok();
    };
    std::vector<Rerun> reruns;
    const auto hand_of = [&](int64_t g, int v, int h) {
      return &out.data[at(
          g - capture_first, v, h == 0 ? wholebody::kLeftHandFirst : wholebody::kRightHandFirst)];
    };
    for (int v = 0; v < views; ++v) {
      for (int64_t i = 0; i < n; ++i) {
        hands.swapped += checks[i].swapped[v];
        for (int h = 0; h < 2; ++h) {
          const HandViewCheck& c = checks[i].views[v][h];
          hands.hands_judged += c.judged ? 1 : 0;
          if (!c.disagrees) continue;
          ++hands.disagreeing;
          if (options.hands.rerun && c.recrop) {
            Rerun r;
            r.view = v;
            r.frame = first + i;
            r.hand = h;
            r.roi = *c.recrop;
            reruns.push_back(r);
          } else {
            const int64_t lowered = DownWeightHand(options.hands, hand_of(first + i, v, h));
            hands.points_down_weighted += lowered;
            ++hands.hands_down_weighted;
          }
        }
      }
    }
    for (const FrameHandCheck& c : checks) hands.points_down_weighted += c.points_down_weighted;
    // The re-runs: the hand landmarker alone, on each worker's tracker (its state is not
    // touched), frames read again (the frame of the previous item reused).
    struct Cached {
      int view = -1;
      int64_t frame = -1;
      media::Image image;
    };
    std::vector<Cached> cached(pool.size());
    ParallelFor(
        static_cast<int64_t>(reruns.size()),
        workers,
        [&](int64_t k, int t) {
          Worker& w = pool[t];
          Rerun& r = reruns[k];
          if (!w.tracker) {
            auto tracker = detect::WholeBodyTracker::Create(detector);
            if (!tracker.ok()) {
              r.status = tracker.status();
              return;
            }
            w.tracker.emplace(std::move(*tracker));
          }
          Cached& c = cached[t];
          if (c.view != r.view || c.frame != r.frame) {
            auto reader_it = w.readers.find(r.view);
            if (reader_it == w.readers.end()) {
              reader_it =
                  w.readers.emplace(r.view, CaptureFrameReader(manifest, r.view, inputs[r.view]))
                      .first;
            }
            c.view = -1;
            StatusOr<bool> read = reader_it->second.Read(r.frame, &c.image);
            if (!read.ok()) {
              r.status = read.status();
              return;
            }
            if (!*read) return;  // dropped: cannot happen for a detected hand
            c.view = r.view;
            c.frame = r.frame;
          }
          StatusOr<double> presence = w.tracker->LandmarkHand(c.image, r.roi, r.points.data());
          if (!presence.ok()) {
            r.status = presence.status();
            return;
          }
          r.presence = *presence;
        },
        /*chunk=*/4);
    for (Rerun& r : reruns) {
      ARCO_RETURN_IF_ERROR(r.status);
      ++hands.recropped;
      const HandConsensus& consensus = checks[r.frame - first].consensus[r.hand];
      const Camera& camera = inputs[r.view].calibration;
      const HandViewCheck& c = checks[r.frame - first].views[r.view][r.hand];
      float* hand = hand_of(r.frame, r.view, r.hand);
      float* again = &r.points[0].x_px;
      const double error = HandErrorPx(options.hands, consensus, camera, again);
      if (r.presence >= detector.min_hand_presence && error <= c.gate_px) {
        std::copy(again, again + 3 * kHandPoints, hand);
        ++hands.fixed;
        hands.points_down_weighted +=
            DownWeightPointsOffConsensus(options.hands, consensus, camera, hand);
      } else {
        hands.points_down_weighted += DownWeightHand(options.hands, hand);
        ++hands.hands_down_weighted;
      }
    }
    hands.wall_s = SecondsSince(hands_start);
  }

  DetectStageSummary summary;
  summary.layout = layout_name;
  summary.first_frame = first;
  summary.last_frame = last;
  summary.points = points;
  summary.kept_other_points = kept;
  summary.hands = hands;
  summary.cameras.resize(views);
  for (int v = 0; v < views; ++v) {
    summary.cameras[v].camera = inputs[v].camera;
    summary.cameras[v].video = inputs[v].video;
  }
  for (size_t i = 0; i < chunks.size(); ++i) {
    DetectCameraSummary& c = summary.cameras[chunks[i].view];
    c.frames += chunk_read[i];
    c.dropped += chunk_dropped[i];
    c.tracker.Merge(chunk_summary[i]);
    summary.total.Merge(chunk_summary[i]);
  }
  for (const Worker& w : pool) {
    summary.decode_s += w.decode_s;
    summary.decode_wait_s += w.decode_wait_s;
  }

  // --- Both files replaced together ----------------------------------------------------
  ARCO_RETURN_IF_ERROR(WriteNpy(npy_tmp, out));
  manifest.keypoints2d = kKeypointsFile;
  manifest.layout = layout_name;
  manifest.keypoint_names.clear();
  ARCO_RETURN_IF_ERROR(WriteJsonFile(manifest_tmp, CaptureManifestToJson(manifest)));
  summary.wall_s = SecondsSince(start);
  // The options as applied and what they found; times are not deterministic and are
  // left out, so the report is the same bit for bit for any thread count.
  Json report_summary = ToJson(summary);
  report_summary.erase("decode_s");
  report_summary.erase("decode_wait_s");
  report_summary.erase("wall_s");
  report_summary["hands"].erase("wall_s");
  // Which runtime ran each model (network.h) is kept: it decides the keypoints' last bits.
  Json runtimes = Json::object();
  for (const Json& m : report_summary["total"]["models"])
    runtimes[m["model"].get<std::string>()] = m["runtime"];
  report_summary["runtimes"] = runtimes;
  for (Json* j : {&report_summary["total"]}) {
    j->erase("models");
    j->erase("inference_s");
    j->erase("preprocess_s");
    j->erase("postprocess_s");
  }
  for (Json& j : report_summary["cameras"]) {
    j.erase("models");
    j.erase("inference_s");
    j.erase("preprocess_s");
    j.erase("postprocess_s");
  }
  ARCO_RETURN_IF_ERROR(WriteJsonFile(report_tmp,
                                     Json{{"format", "arco-detect-report"},
                                          {"options", ToJson(options)},
                                          {"summary", report_summary}}));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  return summary;
}

}  // namespace arco::capture
