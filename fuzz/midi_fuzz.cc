// Fuzzes the Standard MIDI File reader of `arco synth --midi`: any bytes must
// give a score or an error, never a crash or a hang.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/synth/midi_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  auto score = arco::synth::ParseMidiScore(bytes, "fuzz.mid");
  if (score.ok()) (void)score->notes.size();
  return 0;
}
