// Where arco finds its own data (the viewer's page and three.js, the detector models, the
// Snakemake workflow) at run time, so that an installed arco runs wherever its prefix is
// put (docs/install.md):
//   1. $ARCO_DATA_DIR (`arco --data-dir DIR` sets it), when set;
//   2. else, for an installed arco (PREFIX/bin/arco beside PREFIX/share/arco), that
//      share/arco folder, found from this executable's own path (/proc/self/exe), so a
//      moved or copied prefix still works;
//   3. else "": an arco run from its build folder, whose callers use the source tree's
//      paths compiled in (ARCO_VIEW_WEB_DIR, ARCO_MODELS_DIR, ...).
// An installed arco never looks into the source or build tree it was built from.
//
// Layout of the data folder (what `cmake --install` writes under PREFIX/share/arco):
//   view/web/          index.html, viewer.js, viewer.css
//   view/three.min.js  three.js's classic build (npm `three`)
//   models/            the converted detector models (when fetched: scripts/fetch_models)
//   workflow/          the Snakemake workflow of `arco batch`
#pragma once

#include <string>

namespace arco {

inline constexpr char kDataDirEnv[] = "ARCO_DATA_DIR";

// This process's executable (/proc/self/exe resolved); "" when it cannot be read.
std::string ExecutablePath();

// The installed data folder of an executable at `executable` (EXE_DIR/../share/arco, the
// relative path fixed by the build's install layout) when that folder exists, else "".
std::string InstalledDataDir(const std::string& executable);

// The data folder (1. or 2. above), "" for a build-tree arco.
std::string DataDir();

// `relative` inside DataDir() when there is one, else `build_tree_path` (a source-tree
// path compiled in).
std::string DataPath(const std::string& relative, const std::string& build_tree_path);

// What a message about a missing data file adds: where the data folder came from and how
// to point arco at another one.
std::string DataDirHint();

}  // namespace arco
