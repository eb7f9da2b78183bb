// A result is tied to what made it (docs/architecture.md, "Results are tied to their
// inputs"): the stages record the fingerprints of the capture files they read, every
// reader (ReadHeader) compares them with the files as they are now, and writing a stage
// removes the stages after it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "arco/mocap/sample_manifest.h"
#include "arco/pipeline/capture_inputs.h"
#include "arco/pipeline/result_folder.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco::pipeline {
namespace {

using arco::testing::SampleManifest;
using arco::testing::TempDir;

constexpr std::initializer_list<const char*> kAllRoles = {
    kManifestInput, kCalibrationInput, kKeypoints2dInput, kAudioInput};

// DIR/cap: stand-ins for the capture's files (their bytes are all that is fingerprinted);
// DIR/res: its result, triangulated.
class ResultInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(MakeDirectories(cap_).ok());
    for (const char* f : {"capture.json", "calibration.xml", "keypoints2d.npy", "audio.wav"}) {
      ASSERT_TRUE(AtomicWriteFile(cap_ + "/" + f, std::string(f) + " contents").ok());
    }
    auto inputs = FingerprintCaptureInputs(cap_, manifest_, kAllRoles);
    ASSERT_TRUE(inputs.ok()) << inputs.status().message();
    inputs_ = *inputs;
    ASSERT_EQ(inputs_.size(), 4u);
    Triangulate();
  }

  void Triangulate() {
    SequenceTriangulation raw;
    raw.points3d.shape = {4, 142, 3};
    raw.points3d.data.assign(4 * 142 * 3, 1.0);
    raw.rms_reprojection_px.shape = raw.num_inliers.shape = raw.num_views.shape = {4, 142};
    raw.rms_reprojection_px.data.assign(4 * 142, 1.0f);
    raw.num_inliers.data.assign(4 * 142, 2);
    raw.num_views.data.assign(4 * 142, 2);
    raw.inlier_mask.shape = {4, 142, 2};
    raw.inlier_mask.data.assign(4 * 142 * 2, 1);
    TriangulationRecord record;
    record.capture_dir = cap_;
    record.units = "m";
    record.inputs = SelectInputs(inputs_, {kManifestInput, kCalibrationInput, kKeypoints2dInput});
    auto removed = result_.WriteTriangulation(
        manifest_, *FindKeypointLayout("spd_cello"), raw, raw.points3d, record);
    ASSERT_TRUE(removed.ok()) << removed.status().message();
    removed_ = *removed;
  }

  // Every later stage, each recording what it read.
  void WriteLaterStages() {
    InstrumentRecord instrument;
    instrument.strings_mm.shape = {4, 4, 2, 3};
    instrument.strings_mm.data.assign(4 * 4 * 2 * 3, 0.0);
    instrument.keypoints_mm.shape = {4, 9, 3};
    instrument.keypoints_mm.data.assign(4 * 9 * 3, 0.0);
    instrument.world_units_per_mm = 0.001;
    instrument.inputs = SelectInputs(inputs_, {kManifestInput});
    ASSERT_TRUE(result_.WriteInstrument(instrument).ok());
    HandRecord hand;
    hand.hands.resize(4);
    hand.inputs = SelectInputs(inputs_, {kManifestInput, kCalibrationInput, kKeypoints2dInput});
    ASSERT_TRUE(result_.WriteHand(hand).ok());
    PitchRecord pitch;
    pitch.inputs = SelectInputs(inputs_, {kManifestInput, kAudioInput});
    ASSERT_TRUE(result_.WritePitch(pitch).ok());
    for (const char* method : {"vision", "paper", "arco"}) {
      MethodRecord m;
      m.method = method;
      m.layout = "spd_cello_contact";
      m.points3d.shape = {4, 155, 3};
      m.points3d.data.assign(4 * 155 * 3, 0.0);
      m.hands.resize(4);
      ASSERT_TRUE(result_.WriteMethod(m).ok());
    }
  }

  Json Manifest() const {
    auto m = result_.ReadManifest();
    EXPECT_TRUE(m.ok());
    return m.ok() ? *m : Json();
  }
  std::string Changed(const std::string& file) const {
    return cap_ + "/" + file + " changed since the result " + res_ +
           " was made (re-run `arco run`)";
  }
  std::string HeaderError() const {
    auto header = result_.ReadHeader();
    return header.ok() ? "ok" : header.status().message();
  }

  TempDir dir_;
  const std::string cap_ = dir_ / "cap";
  const std::string res_ = dir_ / "res";
  const ResultFolder result_{res_};
  const CaptureManifest manifest_ = SampleManifest();
  CaptureInputs inputs_;
  std::vector<std::string> removed_;
};

TEST_F(ResultInputs, TriangulationRecordsTheFilesItRead) {
  const Json m = Manifest();
  for (const Json* inputs : {&m["inputs"], &m["stages"]["triangulation"]["inputs"]}) {
    ASSERT_EQ(inputs->size(), 3u) << inputs->dump();
    EXPECT_EQ((*inputs)["capture.json"]["file"], "capture.json");
    EXPECT_EQ((*inputs)["calibration"]["file"], "calibration.xml");
    EXPECT_EQ((*inputs)["keypoints2d"]["file"], "keypoints2d.npy");
    EXPECT_EQ((*inputs)["keypoints2d"]["size_bytes"], 24);  // "keypoints2d.npy contents"
    EXPECT_EQ((*inputs)["keypoints2d"]["murmur3"],
              FingerprintBytes("keypoints2d.npy contents").murmur3);
  }
  EXPECT_TRUE(removed_.empty());
  EXPECT_EQ(HeaderError(), "ok");
}

// Each file the result was made from, changed in one byte (same size), or gone.
TEST_F(ResultInputs, AReaderRefusesAChangedOrMissingInput) {
  WriteLaterStages();  // the audio is recorded by the pitch stage only
  for (const char* file : {"capture.json", "calibration.xml", "keypoints2d.npy", "audio.wav"}) {
    const std::string path = cap_ + "/" + file;
    const std::string original = *ReadFileToString(path);
    std::string changed = original;
    changed[0] = static_cast<char>(changed[0] ^ 1);
    ASSERT_TRUE(AtomicWriteFile(path, changed).ok());
    EXPECT_EQ(HeaderError(), Changed(file));
    EXPECT_EQ(result_.CheckInputs().message(), Changed(file));
    // Listing paths does not compare (cli/command_paths.h).
    EXPECT_TRUE(result_.ReadHeader(InputCheck::kSkip).ok());
    std::filesystem::remove(path);
    EXPECT_EQ(
        HeaderError(),
        path + " changed since the result " + res_ + " was made (it is gone; re-run `arco run`)");
    ASSERT_TRUE(AtomicWriteFile(path, original).ok());
    EXPECT_EQ(HeaderError(), "ok") << file;
  }
}

// A stage's own record is compared too, not only the result's summary of them.
TEST_F(ResultInputs, AStageEntryIsComparedToo) {
  WriteLaterStages();
  Json m = Manifest();
  m["stages"]["hand"]["inputs"]["calibration"]["murmur3"] = FingerprintBytes("other").murmur3;
  ASSERT_TRUE(WriteJsonFile(result_.ManifestPath(), m).ok());
  EXPECT_EQ(HeaderError(), Changed("calibration.xml"));
}

TEST_F(ResultInputs, AResultOfAnOlderArcoIsReadWithoutComparing) {
  Json m = Manifest();
  m.erase("inputs");
  m["stages"]["triangulation"].erase("inputs");
  ASSERT_TRUE(WriteJsonFile(result_.ManifestPath(), m).ok());
  ASSERT_TRUE(AtomicWriteFile(cap_ + "/calibration.xml", "another calibration").ok());
  EXPECT_EQ(HeaderError(), "ok");
}

TEST_F(ResultInputs, AMalformedRecordNamesTheField) {
  Json m = Manifest();
  m["inputs"]["calibration"].erase("murmur3");
  ASSERT_TRUE(WriteJsonFile(result_.ManifestPath(), m).ok());
  EXPECT_EQ(
      HeaderError(),
      result_.ManifestPath() + ": \"inputs\" entry 'calibration' has no \"murmur3\" (a string)");
  m = Manifest();
  m["inputs"]["calibration"]["murmur3"] = FingerprintBytes("calibration.xml contents").murmur3;
  m["stages"]["triangulation"]["inputs"]["keypoints2d"]["size_bytes"] = -1;
  ASSERT_TRUE(WriteJsonFile(result_.ManifestPath(), m).ok());
  EXPECT_EQ(HeaderError(),
            result_.ManifestPath() +
                ": \"stages.triangulation.inputs\" entry 'keypoints2d' has "
                "no \"size_bytes\" (an integer >= 0)");
}

// The stages of `arco run` compare the result they extend with the capture they opened.
TEST_F(ResultInputs, CheckInputsMatchComparesTheGivenFingerprints) {
  EXPECT_TRUE(result_.CheckInputsMatch(inputs_).ok());
  EXPECT_TRUE(result_.CheckInputsMatch({}).ok());  // nothing in common
  CaptureInputs other = inputs_;
  other[kKeypoints2dInput].fingerprint = FingerprintBytes("re-detected");
  EXPECT_EQ(result_.CheckInputsMatch(other).message(), Changed("keypoints2d.npy"));
  // The audio is not the triangulation's: nothing to compare it with yet.
  other = inputs_;
  other[kAudioInput].fingerprint = FingerprintBytes("another recording");
  EXPECT_TRUE(result_.CheckInputsMatch(other).ok());
}

// Re-running a stage removes every stage after it (kStageOrder), files and entries, and
// names them in "removed_stages"; the method folders do not remove one another.
TEST_F(ResultInputs, WritingAStageRemovesTheLaterStages) {
  WriteLaterStages();
  const std::vector<std::string> all = {
      "triangulation", "instrument", "hand", "pitch", "vision", "paper", "arco"};
  Json m = Manifest();
  for (const std::string& stage : all) EXPECT_TRUE(m["stages"].contains(stage)) << stage;
  EXPECT_FALSE(m.contains("removed_stages"));
  ASSERT_TRUE(FileExists(res_ + "/pitch.csv") && FileExists(res_ + "/notes.csv"));

  // A method again: the others stay.
  MethodRecord arco;
  arco.method = "arco";
  arco.layout = "spd_cello_contact";
  arco.points3d.shape = {4, 155, 3};
  arco.points3d.data.assign(4 * 155 * 3, 0.0);
  arco.hands.resize(4);
  ASSERT_TRUE(result_.WriteMethod(arco).ok());
  EXPECT_EQ(Manifest()["stages"].size(), all.size());

  // The hand stage again: pitch and the methods go.
  HandRecord hand;
  hand.hands.resize(4);
  ASSERT_TRUE(result_.WriteHand(hand).ok());
  m = Manifest();
  EXPECT_EQ(m["removed_stages"], Json::array({"pitch", "arco", "paper", "vision"}));
  for (const char* gone : {"pitch", "vision", "paper", "arco"}) {
    EXPECT_FALSE(m["stages"].contains(gone)) << gone;
  }
  for (const char* gone : {"pitch.csv", "notes.csv", "vision", "paper", "arco"}) {
    EXPECT_FALSE(FileExists(res_ + "/" + gone)) << gone;
  }
  EXPECT_TRUE(FileExists(res_ + "/hand/hand_params.npy"));
  EXPECT_TRUE(FileExists(res_ + "/instrument/strings.npy"));

  // The triangulation again: everything after it goes; a stage written again leaves the
  // list, and the run's options (no longer what made the folder) go.
  m["options"] = {{"num_threads", 0}};
  ASSERT_TRUE(WriteJsonFile(result_.ManifestPath(), m).ok());
  Triangulate();
  EXPECT_EQ(removed_, (std::vector<std::string>{"instrument", "hand"}));
  m = Manifest();
  EXPECT_EQ(m["stages"].size(), 1u);
  EXPECT_EQ(m["removed_stages"],
            Json::array({"pitch", "arco", "paper", "vision", "instrument", "hand"}));
  EXPECT_FALSE(m.contains("options"));
  EXPECT_EQ(m["inputs"].size(), 3u);  // the audio was the pitch stage's
  std::vector<std::string> entries;
  for (const auto& e : std::filesystem::directory_iterator(res_)) {
    entries.push_back(e.path().filename().string());
  }
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"result.json", "triangulation"}));
  WriteLaterStages();
  EXPECT_FALSE(Manifest().contains("removed_stages"));
}

// A stage entry whose "dir" leaves the result folder is an error, and nothing is removed.
TEST_F(ResultInputs, AStageOutsideTheResultIsNeverRemoved) {
  ASSERT_TRUE(MakeDirectories(dir_ / "elsewhere").ok());
  Json m = Manifest();
  m["stages"]["hand"] = {{"dir", "../elsewhere"}};
  ASSERT_TRUE(WriteJsonFile(result_.ManifestPath(), m).ok());
  InstrumentRecord instrument;
  instrument.world_units_per_mm = 0.001;
  const Status s = result_.WriteInstrument(instrument);
  EXPECT_EQ(s.message(),
            result_.ManifestPath() +
                ": stage 'hand' names '../elsewhere': not a name inside the result folder");
  EXPECT_TRUE(std::filesystem::is_directory(dir_ / "elsewhere"));
  EXPECT_FALSE(FileExists(res_ + "/instrument"));
  EXPECT_EQ(Manifest(), m);
}

}  // namespace
}  // namespace arco::pipeline
