# `make package`: the Debian package arco_VERSION_amd64.deb (CPack's DEB generator) of what
# `cmake --install` installs, under /usr. Its Depends: come from the shared libraries arco
# and the Python module link (dpkg-shlibdeps), so `apt install ./arco_*.deb` on a fresh
# Debian 12 brings in everything `arco` needs; programs arco runs but does not link are
# Recommends (fluidsynth renders `arco synth`'s audio) or Suggests (snakemake runs
# `arco batch`). Only install rules put files in it: no test or benchmark binaries.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME arco)
set(CPACK_PACKAGE_VENDOR arco)
set(ARCO_PACKAGE_CONTACT "arco <arco@localhost>" CACHE STRING
    "The .deb's Maintainer: (set a real address for a package that is distributed)")
set(CPACK_PACKAGE_CONTACT "${ARCO_PACKAGE_CONTACT}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "audio-guided markerless motion capture of string-instrument performance")
# Lines under 80 characters (Debian policy for the extended description).
set(CPACK_PACKAGE_DESCRIPTION
    "arco triangulates the performer, the instrument, its strings and the bow
from many calibrated cameras, and uses the sound of the performance to
correct what the cameras get wrong. It reports 3D motion, the fingering of
every note and how accurate it is. This package holds the arco command,
its man pages and bash completion, the viewer's web page, the detector
models (when the build had them) and the Python module arco.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # arco_0.1.0_amd64.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The Python module's interpreter (src/arco/python/CMakeLists.txt), when it is built.
get_property(arco_python_recommends GLOBAL PROPERTY ARCO_DEB_PYTHON_RECOMMENDS)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "${arco_python_recommends}fluidsynth, fluid-soundfont-gm")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "snakemake")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_STRIP_FILES ON)
# The folder `make package` leaves the .deb in: the build folder.
set(CPACK_PACKAGE_DIRECTORY ${CMAKE_BINARY_DIR})
include(CPack)
