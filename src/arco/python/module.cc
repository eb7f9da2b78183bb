// `import arco`: the Python bindings (docs/python.md). A thin layer over the libraries:
// arrays in and out as numpy (results are moved into arrays that own them, no copies),
// options as keyword arguments checked by the options structs' Validate(), errors as
// Python exceptions carrying the library's one-line messages (bindings.h). Long C++ work
// runs with the GIL released. One file per layer; this one only assembles the module.
#include "arco/python/bindings.h"

PYBIND11_MODULE(arco, m) {
  using namespace arco::python;
  m.doc() = "arco: markerless motion capture of string players (docs/python.md)";
  m.attr("__version__") = ARCO_VERSION_STRING;
  BindCalibration(m);
  BindTriangulate(m);
  BindPitch(m);
  BindInstrument(m);
  BindHand(m);
  BindEval(m);
  BindResult(m);
  BindRun(m);
  BindStages(m);
}
