#include "arco/util/file_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <string>
#include <thread>
#include <utility>

#include "arco/testing/temp_dir.h"

namespace arco {
namespace {

using arco::testing::TempDir;

TEST(FileBytes, MapsARegularFileAndKeepsItsBytesAfterAMove) {
  TempDir dir;
  std::string contents(1 << 20, '\0');
  for (size_t i = 0; i < contents.size(); ++i) contents[i] = static_cast<char>((i * 131) % 251);
  ASSERT_TRUE(AtomicWriteFile(dir / "a.bin", contents).ok());
  auto bytes = FileBytes::Open(dir / "a.bin");
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  const FileBytes moved = std::move(*bytes);
  EXPECT_EQ(moved.view(), contents);
  // Replaced on disk the way arco writes (a new file renamed over it): the bytes held
  // are still the old file's.
  ASSERT_TRUE(AtomicWriteFile(dir / "a.bin", "new").ok());
  EXPECT_EQ(moved.view(), contents);
}

TEST(FileBytes, ReadsAnEmptyFileAndAFifo) {
  TempDir dir;
  ASSERT_TRUE(AtomicWriteFile(dir / "empty", "").ok());
  auto empty = FileBytes::Open(dir / "empty");
  ASSERT_TRUE(empty.ok()) << empty.status().message();
  EXPECT_TRUE(empty->view().empty());
  // A named pipe cannot be mapped: its bytes are read until the writer closes it.
  const std::string fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    FILE* f = std::fopen(fifo.c_str(), "wb");
    if (f == nullptr) return;
    std::fputs("streamed", f);
    std::fclose(f);
  });
  auto piped = FileBytes::Open(fifo);
  writer.join();
  ASSERT_TRUE(piped.ok()) << piped.status().message();
  EXPECT_EQ(piped->view(), "streamed");
}

TEST(FileBytes, NamesAMissingFileAndAFolder) {
  TempDir dir;
  EXPECT_EQ(FileBytes::Open(dir / "nope.npy").status().message(),
            dir / "nope.npy" + ": file not found");
  EXPECT_EQ(FileBytes::Open(dir.path()).status().message(),
            dir.path() + ": is a directory, expected a file");
}

}  // namespace
}  // namespace arco
