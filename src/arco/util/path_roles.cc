#include "arco/util/path_roles.h"

#include <filesystem>
#include <system_error>

#include "arco/util/output_set.h"

namespace arco {
namespace fs = std::filesystem;
namespace {

// Resolved paths are the same file: the same name, or (both existing) the same device and
// inode (a hard link, a bind mount).
bool SamePath(const std::string& a, const std::string& b) {
  if (a == b) return true;
  std::error_code ec;
  return fs::equivalent(a, b, ec) && !ec;
}

// " (PATH)" when the user's text differs from the output's, to show which file is meant.
std::string Where(const std::string& path, const std::string& output) {
  return path == output ? "" : " (" + path + ")";
}

}  // namespace

std::string ResolvePath(const std::string& given) {
  const std::string path = NormalizeOutputPath(given);
  if (path.empty()) return path;
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  if (ec) return path;
  fs::path resolved = fs::weakly_canonical(absolute, ec);
  if (ec) resolved = absolute.lexically_normal();
  std::string out = resolved.string();
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  return out;
}

bool PathIsInside(const std::string& inner, const std::string& outer) {
  const fs::path in(inner), out(outer);
  auto i = in.begin();
  for (auto o = out.begin(); o != out.end(); ++o, ++i) {
    if (o->empty()) continue;  // "/" root's trailing empty element
    if (i == in.end() || *i != *o) return false;
  }
  return i != in.end();
}

void PathRoles::AddInput(const std::string& label, const std::string& path) {
  if (!path.empty()) inputs_.push_back({label, path, false});
}

void PathRoles::AddOwnedFolder(const std::string& label, const std::string& path) {
  if (!path.empty()) inputs_.push_back({label, path, true});
}

void PathRoles::AddOutput(const std::string& label, const std::string& path) {
  if (path.empty()) return;
  outputs_.push_back({label, path, false});
  output_paths_.push_back(path);
}

Status PathRoles::Check() const {
  std::vector<std::string> inputs, outputs;
  for (const Entry& e : inputs_) inputs.push_back(ResolvePath(e.path));
  for (const Entry& e : outputs_) outputs.push_back(ResolvePath(e.path));
  const char* kReplaces = "; an output never replaces an input (choose another path)";
  for (size_t o = 0; o < outputs_.size(); ++o) {
    const Entry& out = outputs_[o];
    const std::string shown = NormalizeOutputPath(out.path);
    // The file itself first: "is the input" says more than "inside its folder".
    for (size_t i = 0; i < inputs_.size(); ++i) {
      if (SamePath(outputs[o], inputs[i])) {
        return Status::Error(shown + ": " + out.label + " is the input " + inputs_[i].label +
                             Where(NormalizeOutputPath(inputs_[i].path), shown) + kReplaces);
      }
    }
    for (size_t i = 0; i < inputs_.size(); ++i) {
      const Entry& in = inputs_[i];
      if (!in.owned && PathIsInside(outputs[o], inputs[i])) {
        return Status::Error(shown + ": " + out.label + " is inside the input folder " +
                             in.label + Where(NormalizeOutputPath(in.path), shown) +
                             "; an output never goes into an input (choose a path outside it)");
      }
      if (PathIsInside(inputs[i], outputs[o])) {
        return Status::Error(shown + ": " + out.label + " contains the input " + in.label +
                             Where(NormalizeOutputPath(in.path), shown) + kReplaces);
      }
    }
    for (size_t k = 0; k < o; ++k) {
      if (SamePath(outputs[o], outputs[k])) {
        return Status::Error(shown + ": given for two outputs (" + outputs_[k].label + " and " +
                             out.label + ")");
      }
    }
  }
  return Status::Ok();
}

}  // namespace arco
