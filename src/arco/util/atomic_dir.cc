#include "arco/util/atomic_dir.h"

namespace arco {

Status AtomicWriteDirectory(const std::string& dir,
                            const FolderReplace& replace,
                            const std::function<Status(const std::string& tmp_dir)>& write) {
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string tmp_dir, outputs.AddFolder(dir, replace));
  ARCO_RETURN_IF_ERROR(write(tmp_dir));
  return outputs.Commit();
}

Status AtomicWriteDirectory(const std::string& dir,
                            const std::function<Status(const std::string& tmp_dir)>& write) {
  FolderReplace any;
  any.overwrite = true;
  return AtomicWriteDirectory(dir, any, write);
}

}  // namespace arco
