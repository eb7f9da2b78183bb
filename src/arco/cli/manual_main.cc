// arco_manual OUT_DIR: writes the `arco` manual generated from the commands' definitions
// (cli/manual.h) at build time: OUT_DIR/man1/*.1 (the folder replaced whole, so a removed
// command leaves no page; the build then compresses them) and OUT_DIR/completions/arco.
#include <cstdio>
#include <filesystem>
#include <string>

#include "arco/cli/app.h"
#include "arco/cli/manual.h"
#include "arco/util/file_io.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: arco_manual OUT_DIR\n");
    return 2;
  }
  namespace fs = std::filesystem;
  const arco::cli::App app = arco::cli::BuildApp();
  const fs::path out = argv[1];
  std::error_code ec;
  fs::remove_all(out / "man1", ec);
  arco::Status status = arco::MakeDirectories((out / "man1").string());
  if (status.ok()) status = arco::MakeDirectories((out / "completions").string());
  for (const arco::cli::ManPage& page : arco::cli::ManPages(app)) {
    if (!status.ok()) break;
    status = arco::AtomicWriteFile((out / "man1" / (page.name + ".1")).string(), page.text);
  }
  if (status.ok()) {
    status = arco::AtomicWriteFile((out / "completions" / "arco").string(),
                                   arco::cli::BashCompletion(app));
  }
  if (!status.ok()) {
    std::fprintf(stderr, "arco_manual: %s\n", status.message().c_str());
    return 1;
  }
  return 0;
}
