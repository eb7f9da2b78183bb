// libsndfile-backed AudioReader (WAV, FLAC, OGG/Vorbis, AIFF, ...), from a file
// or from memory through SF_VIRTUAL_IO.
#include <sndfile.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <vector>

#include "arco/audio/audio_reader.h"

namespace arco::audio {
namespace {

// Largest block decoded at once (frames); bounds memory for any channel count.
constexpr int64_t kBlockFrames = 4096;
constexpr int kMaxChannels = 1024;

struct MemoryFile {
  const std::string* bytes = nullptr;
  sf_count_t position = 0;
};

sf_count_t MemLength(void* user) {
  return static_cast<sf_count_t>(static_cast<MemoryFile*>(user)->bytes->size());
}
sf_count_t MemSeek(sf_count_t offset, int whence, void* user) {
  auto* f = static_cast<MemoryFile*>(user);
  const sf_count_t size = static_cast<sf_count_t>(f->bytes->size());
  sf_count_t target = offset;
  if (whence == SEEK_CUR) target = f->position + offset;
  if (whence == SEEK_END) target = size + offset;
  if (target < 0) return -1;
  f->position = std::min(target, size);
  return f->position;
}
sf_count_t MemRead(void* ptr, sf_count_t count, void* user) {
  auto* f = static_cast<MemoryFile*>(user);
  const sf_count_t size = static_cast<sf_count_t>(f->bytes->size());
  const sf_count_t n = std::max<sf_count_t>(0, std::min(count, size - f->position));
  if (n > 0) std::memcpy(ptr, f->bytes->data() + f->position, static_cast<size_t>(n));
  f->position += n;
  return n;
}
sf_count_t MemWrite(const void*, sf_count_t, void*) { return 0; }
sf_count_t MemTell(void* user) { return static_cast<MemoryFile*>(user)->position; }

// The frames a RIFF/WAVE header promises (its data chunk's size over the fmt chunk's
// block size), or -1 when it does not say (not a WAV, a streaming size of 0 or ~0, a
// compressed format). libsndfile silently shortens a truncated file's length to what is
// there; comparing the two tells a truncated file. `read(offset, n)` returns up to n bytes.
template <typename Read>
int64_t WavPromisedFrames(const Read& read) {
  auto u32 = [](const std::string& b, size_t at) {
    return static_cast<uint32_t>(static_cast<unsigned char>(b[at])) |
           static_cast<uint32_t>(static_cast<unsigned char>(b[at + 1])) << 8 |
           static_cast<uint32_t>(static_cast<unsigned char>(b[at + 2])) << 16 |
           static_cast<uint32_t>(static_cast<unsigned char>(b[at + 3])) << 24;
  };
  const std::string riff = read(0, 12);
  if (riff.size() < 12 || riff.compare(0, 4, "RIFF") != 0 || riff.compare(8, 4, "WAVE") != 0) {
    return -1;
  }
  int64_t at = 12;
  int64_t block_align = 0;
  for (int chunks = 0; chunks < 64; ++chunks) {  // bounded: a corrupt file cannot loop
    const std::string head = read(at, 8);
    if (head.size() < 8) return -1;
    const uint32_t size = u32(head, 4);
    if (head.compare(0, 4, "fmt ") == 0) {
      const std::string fmt = read(at + 8, 16);
      if (fmt.size() < 16) return -1;
      const int tag = static_cast<unsigned char>(fmt[0]) | static_cast<unsigned char>(fmt[1]) << 8;
      // PCM, IEEE float, extensible: one block per frame.
      if (tag != 1 && tag != 3 && tag != 0xFFFE) return -1;
      block_align = static_cast<unsigned char>(fmt[12]) | static_cast<unsigned char>(fmt[13]) << 8;
    } else if (head.compare(0, 4, "data") == 0) {
      if (block_align <= 0 || size == 0 || size == 0xFFFFFFFFu) return -1;
      return static_cast<int64_t>(size) / block_align;
    }
    at += 8 + static_cast<int64_t>(size) + (size & 1);
  }
  return -1;
}

class SndfileReader : public AudioReader {
 public:
  ~SndfileReader() override {
    if (file_ != nullptr) sf_close(file_);
  }

  static StatusOr<std::unique_ptr<AudioReader>> Open(const std::string& name,
                                                     const std::string* bytes) {
    std::unique_ptr<SndfileReader> reader(new SndfileReader());
    SF_INFO sf_info;
    std::memset(&sf_info, 0, sizeof(sf_info));
    if (bytes != nullptr) {
      reader->memory_.bytes = bytes;
      static SF_VIRTUAL_IO io = {MemLength, MemSeek, MemRead, MemWrite, MemTell};
      reader->file_ = sf_open_virtual(&io, SFM_READ, &sf_info, &reader->memory_);
    } else {
      reader->file_ = sf_open(name.c_str(), SFM_READ, &sf_info);
    }
    if (reader->file_ == nullptr) {
      return Status::Error(name + ": cannot decode audio: " + sf_strerror(nullptr));
    }
    if (sf_info.samplerate < kMinRateHz || sf_info.samplerate > kMaxRateHz) {
      return Status::Error(name + ": unsupported sample rate (need 1-768 kHz): " +
                           std::to_string(sf_info.samplerate));
    }
    if (sf_info.channels <= 0 || sf_info.channels > kMaxChannels) {
      return Status::Error(name + ": invalid channel count " + std::to_string(sf_info.channels));
    }
    reader->name_ = name;
    reader->info_.sample_rate_hz = sf_info.samplerate;
    reader->info_.channels = sf_info.channels;
    reader->info_.frames = sf_info.frames;
    reader->info_.source = name;
    // A header promising more than the file holds: the promise is the length, so the
    // reader's shortfall is reported (TruncationWarning).
    // The header walk reads a few chunk headers: one stream for all of them (a file
    // opened once per read made `arco run` open audio.wav five times per reader).
    std::ifstream in;
    const int64_t promised = bytes != nullptr ? WavPromisedFrames([&](int64_t at, int64_t n) {
      return at < static_cast<int64_t>(bytes->size()) ? bytes->substr(at, n) : std::string();
    })
                                              : WavPromisedFrames([&](int64_t at, int64_t n) {
                                                  if (!in.is_open()) in.open(name, std::ios::binary);
                                                  in.clear();
                                                  std::string out(static_cast<size_t>(n), '\0');
                                                  in.seekg(at);
                                                  in.read(out.data(), n);
                                                  out.resize(static_cast<size_t>(
                                                      std::max<std::streamsize>(0, in.gcount())));
                                                  return out;
                                                });
    if (promised > sf_info.frames) {
      reader->info_.frames = promised;
      reader->info_.missing_frames = promised - sf_info.frames;
    }
    SF_FORMAT_INFO format_info;
    format_info.format = sf_info.format & SF_FORMAT_TYPEMASK;
    reader->info_.format = "sndfile";
    if (sf_command(reader->file_, SFC_GET_FORMAT_INFO, &format_info, sizeof(format_info)) == 0 &&
        format_info.name != nullptr) {
      reader->info_.format = format_info.name;
    }
    reader->interleaved_.resize(static_cast<size_t>(kBlockFrames * sf_info.channels));
    return std::unique_ptr<AudioReader>(std::move(reader));
  }

  StatusOr<int64_t> ReadMono(float* out, int64_t max_frames) override {
    const int channels = info_.channels;
    int64_t total = 0;
    while (total < max_frames && !eof_) {
      const int64_t want = std::min(kBlockFrames, max_frames - total);
      const sf_count_t got = sf_readf_float(file_, interleaved_.data(), want);
      if (got < 0) return Status::Error(name_ + ": read error: " + sf_strerror(file_));
      if (got == 0) {
        eof_ = true;
        if (sf_error(file_) != SF_ERR_NO_ERROR) {
          return Status::Error(name_ + ": decode error: " + sf_strerror(file_));
        }
        break;
      }
      ARCO_RETURN_IF_ERROR(CheckSamples(
          interleaved_.data(), got * channels, channels, read_, info_.sample_rate_hz, name_));
      const float scale = 1.0f / static_cast<float>(channels);
      for (sf_count_t i = 0; i < got; ++i) {
        float sum = 0.0f;
        const float* frame = interleaved_.data() + i * channels;
        for (int c = 0; c < channels; ++c) sum += frame[c];
        out[total + i] = sum * scale;
      }
      read_ += got;
      total += got;
    }
    return total;
  }

 private:
  SndfileReader() = default;
  SNDFILE* file_ = nullptr;
  MemoryFile memory_;
  std::string name_;
  std::vector<float> interleaved_;
  bool eof_ = false;
  int64_t read_ = 0;  // samples read so far
};

}  // namespace

StatusOr<std::unique_ptr<AudioReader>> OpenAudioWithSndfile(const std::string& path) {
  return SndfileReader::Open(path, nullptr);
}

StatusOr<std::unique_ptr<AudioReader>> OpenAudioFromMemory(const std::string* bytes,
                                                           const std::string& name) {
  return SndfileReader::Open(name, bytes);
}

}  // namespace arco::audio
