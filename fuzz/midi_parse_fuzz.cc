// Fuzzes the MIDI reader: any bytes give events or an error, never a crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/audio/midi_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  auto parsed = arco::audio::ParseMidi(bytes);
  if (parsed.ok()) (void)parsed->events.size();
  return 0;
}
