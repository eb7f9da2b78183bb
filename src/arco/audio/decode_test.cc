// Decoding, downmix and resampling: known signals through every input path.
#include <gtest/gtest.h>
#include <sndfile.h>

#include <cmath>
#include <fstream>

#include "arco/audio/audio_reader.h"
#include "arco/audio/resampler.h"
#include "arco/audio/sample_stream.h"
#include "arco/audio/test_signals.h"
#include "arco/util/file_io.h"

namespace arco::audio {
namespace {

using testing::TempPath;
using testing::WriteWav;

std::vector<float> ReadAll(AudioReader* reader) {
  std::vector<float> all, block(1000);
  while (true) {
    auto n = reader->ReadMono(block.data(), 1000);
    EXPECT_TRUE(n.ok());
    if (!n.ok() || *n == 0) break;
    all.insert(all.end(), block.begin(), block.begin() + *n);
  }
  return all;
}

TEST(OpenAudio, DownmixesStereoWavByAveraging) {
  std::vector<float> stereo;
  for (int i = 0; i < 1000; ++i) {
    stereo.push_back(0.5f);
    stereo.push_back(i % 2 ? 0.25f : -0.25f);
  }
  const std::string path = TempPath("stereo.wav");
  ASSERT_TRUE(WriteWav(path, stereo, 48000, 2, /*float_format=*/true).ok());
  auto reader = OpenAudio(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ((*reader)->info().sample_rate_hz, 48000);
  EXPECT_EQ((*reader)->info().channels, 2);
  EXPECT_EQ((*reader)->info().frames, 1000);
  const auto mono = ReadAll(reader->get());
  ASSERT_EQ(mono.size(), 1000u);
  EXPECT_FLOAT_EQ(mono[0], 0.125f);
  EXPECT_FLOAT_EQ(mono[1], 0.375f);
}

TEST(OpenAudio, ReadsFlacAndOggThroughSndfile) {
  auto tone = testing::RenderTone([](double) { return 440.0; }, 0.5, {});
  for (int format : {SF_FORMAT_FLAC | SF_FORMAT_PCM_16, SF_FORMAT_OGG | SF_FORMAT_VORBIS}) {
    const std::string path = TempPath((format & SF_FORMAT_FLAC) ? "t.flac" : "t.ogg");
    SF_INFO info{};
    info.samplerate = 44100;
    info.channels = 1;
    info.format = format;
    SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
    ASSERT_NE(f, nullptr) << sf_strerror(nullptr);
    sf_writef_float(f, tone.data(), static_cast<sf_count_t>(tone.size()));
    sf_close(f);
    auto reader = OpenAudio(path);
    ASSERT_TRUE(reader.ok()) << reader.status().message();
    const auto decoded = ReadAll(reader->get());
    EXPECT_NEAR(static_cast<double>(decoded.size()), tone.size(), 2048) << path;
  }
}

TEST(OpenAudio, FfmpegAndSndfileAgreeOnWav) {
  auto tone = testing::RenderTone([](double) { return 220.0; }, 0.3, {});
  const std::string path = TempPath("agree.wav");
  ASSERT_TRUE(WriteWav(path, tone, 44100).ok());
  auto a = OpenAudioWithSndfile(path);
  auto b = OpenAudioWithFfmpeg(path);
  ASSERT_TRUE(a.ok() && b.ok());
  const auto sa = ReadAll(a->get()), sb = ReadAll(b->get());
  ASSERT_EQ(sa.size(), sb.size());
  for (size_t i = 0; i < sa.size(); ++i) ASSERT_NEAR(sa[i], sb[i], 1e-6);
}

TEST(OpenAudio, BadInputsGiveOneClearError) {
  EXPECT_NE(OpenAudio("/nonexistent/x.wav").status().message().find("no such file"),
            std::string::npos);
  const std::string empty = TempPath("empty.wav");
  ASSERT_TRUE(AtomicWriteFile(empty, "").ok());
  EXPECT_NE(OpenAudio(empty).status().message().find("empty file"), std::string::npos);
  const std::string garbage = TempPath("garbage.wav");
  ASSERT_TRUE(AtomicWriteFile(garbage, std::string(5000, '\x7f')).ok());
  auto g = OpenAudio(garbage);
  ASSERT_FALSE(g.ok());
  EXPECT_EQ(g.status().message().rfind(garbage + ": cannot decode audio", 0), 0u)
      << g.status().message();
  EXPECT_FALSE(OpenAudio(TempPath("")).ok());  // a directory
}

TEST(OpenAudioFromMemory, DecodesAndRejectsTruncatedHeaders) {
  auto tone = testing::RenderTone([](double) { return 330.0; }, 0.1, {});
  const std::string path = TempPath("mem.wav");
  ASSERT_TRUE(WriteWav(path, tone, 44100).ok());
  auto bytes = ReadFileToString(path);
  ASSERT_TRUE(bytes.ok());
  auto reader = OpenAudioFromMemory(&*bytes, "mem.wav");
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(ReadAll(reader->get()).size(), tone.size());
  const std::string header_only = bytes->substr(0, 20);
  EXPECT_FALSE(OpenAudioFromMemory(&header_only, "cut.wav").ok());
  // Data cut in half: libsndfile clamps the header to the data present, so the
  // reader delivers the samples that exist (about half) and no garbage.
  const std::string half = bytes->substr(0, bytes->size() / 2);
  auto cut = OpenAudioFromMemory(&half, "half.wav");
  ASSERT_TRUE(cut.ok());
  const auto samples = ReadAll(cut->get());
  EXPECT_NEAR(static_cast<double>(samples.size()), tone.size() / 2.0, 40.0);
  for (size_t i = 0; i < samples.size(); ++i) ASSERT_NEAR(samples[i], tone[i], 1e-4);
}

// The header's promise against what a cut file holds: one warning naming the file and the
// seconds missing, from a file and from memory; a whole file has none.
TEST(TruncationWarning, NamesTheFileAndWhatIsMissing) {
  auto tone = testing::RenderTone([](double) { return 330.0; }, 1.0, {});
  const std::string path = TempPath("whole.wav");
  ASSERT_TRUE(WriteWav(path, tone, 44100).ok());
  auto whole = OpenAudio(path);
  ASSERT_TRUE(whole.ok());
  EXPECT_EQ((*whole)->info().frames, 44100);
  EXPECT_EQ(TruncationWarning((*whole)->info()), "");
  auto bytes = ReadFileToString(path);
  ASSERT_TRUE(bytes.ok());
  const size_t data = bytes->find("data") + 8;  // 16-bit mono: 2 bytes a sample
  const std::string cut_path = TempPath("cut.wav");
  ASSERT_TRUE(AtomicWriteFile(cut_path, bytes->substr(0, data + 2 * 11025)).ok());
  auto cut = OpenAudio(cut_path);
  ASSERT_TRUE(cut.ok());
  EXPECT_EQ((*cut)->info().frames, 44100);  // the header's promise
  EXPECT_EQ((*cut)->info().missing_frames, 44100 - 11025);
  EXPECT_EQ(TruncationWarning((*cut)->info()),
            cut_path +
                ": truncated: the header promises 44100 samples (1.000 s), the file "
                "holds 11025 (0.750 s missing)");
  EXPECT_EQ(ReadAll(cut->get()).size(), 11025u);  // what exists, nothing invented
  const std::string half = bytes->substr(0, data + 2 * 22050);
  auto memory = OpenAudioFromMemory(&half, "mem.wav");
  ASSERT_TRUE(memory.ok());
  EXPECT_EQ(TruncationWarning((*memory)->info()),
            "mem.wav: truncated: the header promises 44100 samples (1.000 s), the file holds "
            "22050 (0.500 s missing)");
}

// Resampled sine must equal the sine evaluated at n / output_rate: any timing
// offset or drift shows up as a phase error.
void ExpectExactTiming(int in_rate, int out_rate, double seconds) {
  const double f = 440.0;
  Resampler r(in_rate, out_rate);
  std::vector<float> block(4096), out(8192);
  int64_t in_done = 0, out_done = 0;
  const int64_t total_in = static_cast<int64_t>(seconds * in_rate);
  double max_error = 0;
  int64_t checked = 0;
  auto consume = [&](int64_t n) {
    for (int64_t i = 0; i < n; ++i, ++out_done) {
      const double t = static_cast<double>(out_done) / out_rate;
      // Skip the edges where the zero padding enters the filter.
      if (t < 0.01 || t > seconds - 0.01) continue;
      max_error = std::max(max_error, std::abs(out[i] - 0.5 * std::sin(2 * M_PI * f * t)));
      ++checked;
    }
  };
  while (in_done < total_in) {
    const int64_t n = std::min<int64_t>(4096, total_in - in_done);
    for (int64_t i = 0; i < n; ++i) {
      block[i] = static_cast<float>(0.5 * std::sin(2 * M_PI * f * (in_done + i) / in_rate));
    }
    in_done += n;
    r.Push(block.data(), n);
    while (int64_t got = r.Pull(out.data(), 8192)) consume(got);
  }
  r.Finish();
  while (int64_t got = r.Pull(out.data(), 8192)) consume(got);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(out_done, (total_in * out_rate + in_rate - 1) / in_rate);
  EXPECT_GT(checked, 0);
  EXPECT_LT(max_error, 2e-4) << in_rate << " -> " << out_rate;
}

TEST(Resampler, ExactTimingForCommonRates) {
  ExpectExactTiming(48000, 16000, 2.0);
  ExpectExactTiming(44100, 16000, 2.0);
  ExpectExactTiming(44100, 32000, 1.0);
  ExpectExactTiming(22050, 16000, 1.0);
  ExpectExactTiming(8000, 16000, 1.0);
  ExpectExactTiming(47993, 16000, 1.0);  // L > 4096: interpolated phases
}

TEST(Resampler, NoDriftOverTenMinutes) { ExpectExactTiming(44100, 16000, 600.0); }

TEST(Resampler, RejectsBadRates) {
  EXPECT_THROW(Resampler(0, 16000), std::invalid_argument);
  EXPECT_THROW(Resampler(16000, -1), std::invalid_argument);
}

TEST(SampleStream, WindowsAreZeroOutsideAndStartsMustNotDecrease) {
  std::vector<float> ramp(1000);
  for (int i = 0; i < 1000; ++i) ramp[i] = i / 1000.0f;
  const std::string path = TempPath("ramp.wav");
  ASSERT_TRUE(WriteWav(path, ramp, 16000, 1, true).ok());
  auto reader = OpenAudio(path);
  ASSERT_TRUE(reader.ok());
  SampleStream stream(std::move(*reader), 16000);
  std::vector<float> w(20);
  ASSERT_TRUE(stream.Read(-10, 20, w.data()).ok());
  EXPECT_EQ(w[0], 0.0f);
  EXPECT_FLOAT_EQ(w[15], 5 / 1000.0f);
  ASSERT_TRUE(stream.Read(990, 20, w.data()).ok());
  EXPECT_FLOAT_EQ(w[9], 999 / 1000.0f);
  EXPECT_EQ(w[10], 0.0f);
  EXPECT_TRUE(stream.finished());
  EXPECT_EQ(stream.decoded(), 1000);
  EXPECT_THROW((void)stream.Read(5, 20, w.data()), std::invalid_argument);
}

}  // namespace
}  // namespace arco::audio
