#include "arco/util/output_set.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "arco/util/interrupt.h"

namespace arco {
namespace fs = std::filesystem;
namespace {

// The parent folder of a normalized path ("." for a bare name).
fs::path ParentOf(const std::string& path) {
  const fs::path p(path);
  return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

// Checks that `parent` is a folder, creating it (and its parents) when `create`.
Status CheckParent(const std::string& path, const fs::path& parent, bool create) {
  std::error_code ec;
  const fs::file_status st = fs::status(parent, ec);
  if (fs::is_directory(st)) return Status::Ok();
  if (fs::exists(st)) {
    return Status::Error(path + ": " + parent.string() + " is not a folder");
  }
  if (!create) {
    return Status::Error(path + ": output folder " + parent.string() + " does not exist");
  }
  {
    const std::unique_lock<std::mutex> no_interrupt = HoldOffInterrupts();  // util/interrupt.h
    fs::create_directories(parent, ec);
  }
  if (ec) {
    return Status::Error(path + ": cannot create folder " + parent.string() + ": " + ec.message());
  }
  return Status::Ok();
}

bool IsEmptyFolder(const std::string& path) {
  std::error_code ec;
  return fs::is_empty(path, ec) && !ec;
}

// ".tmp-PID.NAME" / ".old-PID.NAME": the PID (NAME in *name), or -1 for any other entry.
long TemporaryOwner(const std::string& entry, const std::string& what, std::string* name) {
  const std::string prefix = "." + what + "-";
  if (entry.compare(0, prefix.size(), prefix) != 0) return -1;
  const size_t dot = entry.find('.', prefix.size());
  if (dot == std::string::npos || dot == prefix.size() || dot + 1 == entry.size()) return -1;
  const std::string digits = entry.substr(prefix.size(), dot - prefix.size());
  if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  *name = entry.substr(dot + 1);
  return std::stol(digits);
}

bool ProcessAlive(long pid) { return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH; }

}  // namespace

int RemoveStaleTemporaries(const std::string& given) {
  const std::string path = NormalizeOutputPath(given);
  const fs::path p(path);
  const std::string name = p.filename().string();
  if (name.empty() || name == "." || name == "..") return 0;
  const fs::path parent = ParentOf(path);
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    for (const char* what : {"tmp", "old"}) {
      std::string of;
      const long pid = TemporaryOwner(entry, what, &of);
      if (pid <= 0 || pid == ::getpid() || ProcessAlive(pid)) continue;
      // An old output moved aside is deleted only once the new one is in place: otherwise
      // it may be the only copy (a command killed mid-commit), and is left for the user.
      std::error_code missing;
      if (std::string(what) == "old" && !fs::exists(fs::symlink_status(parent / of, missing))) {
        continue;
      }
      std::error_code ignored;
      if (fs::remove_all(it->path(), ignored) > 0 && !ignored) ++removed;
    }
  }
  return removed;
}

std::string NormalizeOutputPath(const std::string& path) {
  if (path.empty()) return path;
  std::string p = fs::path(path).lexically_normal().string();
  while (p.size() > 1 && p.back() == '/') p.pop_back();
  return p;
}

std::string HiddenSibling(const std::string& path, const std::string& what) {
  const fs::path p(NormalizeOutputPath(path));
  // The extension stays last, for writers that choose the format from it.
  const std::string name =
      "." + what + "-" + std::to_string(::getpid()) + "." + p.filename().string();
  return p.has_parent_path() ? (p.parent_path() / name).string() : name;
}

OutputSet::~OutputSet() {
  if (done_) return;
  std::error_code ec;
  for (const Output& o : outputs_) {
    if (o.removal) continue;
    fs::remove_all(o.tmp, ec);
    UntrackTemporary(o.tmp);
  }
}

std::vector<std::string> OutputSet::paths() const {
  std::vector<std::string> out;
  for (const Output& o : outputs_) out.push_back(o.path);
  return out;
}

Status CheckOutputFile(const std::string& given) {
  if (given.empty()) return Status::Error("an output file path is empty");
  if (given.back() == '/') {
    return Status::Error(given + ": names a folder; expected a file path");
  }
  const std::string path = NormalizeOutputPath(given);
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    return Status::Error(path + ": is a folder; expected a file path");
  }
  ARCO_RETURN_IF_ERROR(CheckParent(path, ParentOf(path), /*create=*/false));
  if (::access(ParentOf(path).c_str(), W_OK) != 0) {
    const int err = errno;
    return Status::Error(path + ": cannot write: " + std::strerror(err));
  }
  return Status::Ok();
}

Status CheckOutputFolder(const std::string& given, const FolderReplace& replace) {
  if (given.empty()) return Status::Error("an output folder path is empty");
  const std::string path = NormalizeOutputPath(given);
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) return Status::Error(path + ": exists and is not a folder");
    if (!IsEmptyFolder(path)) {
      if (!replace.overwrite) {
        return Status::Error(path + ": " + replace.kind + " exists and is not empty (" +
                             replace.option + " replaces it)");
      }
      if (!replace.marker.empty() && !fs::exists(fs::path(path) / replace.marker, ec)) {
        return Status::Error(path + ": no " + replace.marker + ": not an arco " + replace.kind +
                             ", so left alone (choose another folder)");
      }
    }
  }
  // The nearest existing ancestor must be a folder we can write into.
  fs::path ancestor = ParentOf(path);
  while (!fs::exists(fs::symlink_status(ancestor, ec)) && ancestor.has_parent_path() &&
         ancestor.parent_path() != ancestor) {
    ancestor = ancestor.parent_path();
  }
  if (!fs::exists(ancestor, ec)) ancestor = ".";
  if (!fs::is_directory(ancestor, ec)) {
    return Status::Error(path + ": cannot create folder: " + ancestor.string() +
                         " is not a folder");
  }
  if (::access(ancestor.c_str(), W_OK) != 0) {
    const int err = errno;
    return Status::Error(path + ": cannot create folder in " + ancestor.string() + ": " +
                         std::strerror(err));
  }
  return Status::Ok();
}

StatusOr<std::string> OutputSet::AddFile(const std::string& given) {
  ARCO_RETURN_IF_ERROR(CheckOutputFile(given));
  const std::string path = NormalizeOutputPath(given);
  for (const Output& o : outputs_) {
    if (o.path == path) return Status::Error(path + ": given for two outputs");
  }
  Output o{path, HiddenSibling(path, "tmp"), HiddenSibling(path, "old"), false};
  RemoveStaleTemporaries(path);
  std::error_code ec;
  fs::remove_all(o.tmp, ec);
  // Tracked and created together, before or after an interrupt's cleanup takes its list.
  const std::unique_lock<std::mutex> no_interrupt = HoldOffInterrupts();
  TrackTemporary(o.tmp);  // removed if the process is interrupted (util/interrupt.h)
  const int fd = ::open(o.tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    UntrackTemporary(o.tmp);
    return Status::Error(path + ": cannot write: " + std::strerror(err));
  }
  ::close(fd);
  outputs_.push_back(o);
  return o.tmp;
}

StatusOr<std::string> OutputSet::AddFolder(const std::string& given, const FolderReplace& replace) {
  ARCO_RETURN_IF_ERROR(CheckOutputFolder(given, replace));
  const std::string path = NormalizeOutputPath(given);
  for (const Output& o : outputs_) {
    if (o.path == path) return Status::Error(path + ": given for two outputs");
  }
  ARCO_RETURN_IF_ERROR(CheckParent(path, ParentOf(path), /*create=*/true));
  Output o{path, HiddenSibling(path, "tmp"), HiddenSibling(path, "old"), true};
  RemoveStaleTemporaries(path);
  std::error_code ec;
  fs::remove_all(o.tmp, ec);
  const std::unique_lock<std::mutex> no_interrupt = HoldOffInterrupts();  // as in AddFile
  TrackTemporary(o.tmp);  // removed if the process is interrupted (util/interrupt.h)
  fs::create_directory(o.tmp, ec);
  if (ec) {
    UntrackTemporary(o.tmp);
    return Status::Error(path + ": cannot create a folder beside it: " + ec.message());
  }
  outputs_.push_back(o);
  return o.tmp;
}

Status OutputSet::AddRemoval(const std::string& given) {
  const std::string path = NormalizeOutputPath(given);
  if (path.empty() || path == "/") return Status::Error("'" + given + "': cannot be removed");
  for (const Output& o : outputs_) {
    if (o.path == path) return Status::Error(path + ": given for two outputs");
  }
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  Output o{path, "", HiddenSibling(path, "old"), fs::is_directory(st)};
  o.removal = true;
  RemoveStaleTemporaries(path);
  outputs_.push_back(o);
  return Status::Ok();
}

Status OutputSet::Commit() {
  if (done_) return Status::Error("output set committed twice");
  done_ = true;
  // An interrupt waits until every output is in place or rolled back (util/interrupt.h);
  // the temporaries are untracked once gone (moved in or removed).
  struct Untrack {
    const std::vector<Output>& outputs;
    ~Untrack() {
      for (const Output& o : outputs) {
        if (!o.removal) UntrackTemporary(o.tmp);
      }
    }
  } untrack{outputs_};
  const std::unique_lock<std::mutex> no_interrupt = HoldOffInterrupts();
  std::error_code ec;
  std::vector<bool> had_old(outputs_.size(), false);
  // Undoes outputs [0, n): the new one out, the old one back.
  auto roll_back = [&](size_t n) {
    std::error_code ignored;
    for (size_t k = n; k-- > 0;) {
      fs::remove_all(outputs_[k].path, ignored);
      if (had_old[k]) fs::rename(outputs_[k].old, outputs_[k].path, ignored);
    }
    for (const Output& o : outputs_) {
      if (!o.removal) fs::remove_all(o.tmp, ignored);
    }
  };
  for (size_t i = 0; i < outputs_.size(); ++i) {
    const Output& o = outputs_[i];
    if (fs::exists(fs::symlink_status(o.path, ec))) {
      fs::remove_all(o.old, ec);
      fs::rename(o.path, o.old, ec);
      if (ec) {
        const std::string why = ec.message();
        roll_back(i);
        return Status::Error(o.path + ": cannot move the old " + (o.folder ? "folder" : "file") +
                             " aside: " + why);
      }
      had_old[i] = true;
    }
    if (o.removal) continue;
    fs::rename(o.tmp, o.path, ec);
    if (ec) {
      const std::string why = ec.message();
      roll_back(i + 1);
      return Status::Error(o.path + ": cannot move into place: " + why);
    }
  }
  for (size_t i = 0; i < outputs_.size(); ++i) {
    if (had_old[i]) fs::remove_all(outputs_[i].old, ec);
  }
  return Status::Ok();
}

}  // namespace arco
