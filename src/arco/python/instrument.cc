// arco.Instrument and arco.contact_point.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arco/instrument/contact.h"
#include "arco/instrument/instrument_model.h"
#include "arco/python/bindings.h"

namespace arco::python {

// ---- instrument ---------------------------------------------------------------------

using PyInstrument = std::shared_ptr<const InstrumentModel>;

PyInstrument MakeInstrument(const std::string& name, double a4_hz) {
  StatusOr<InstrumentKind> kind = ParseInstrumentKind(name);
  CheckValid(kind.status());
  InstrumentOptions options;
  options.kind = *kind;
  options.tuning.a4_hz = a4_hz;
  StatusOr<InstrumentModel> model = InstrumentModel::Create(options);
  CheckValid(model.status());
  return std::make_shared<const InstrumentModel>(std::move(*model));
}

PyInstrument InstrumentFrom(const py::object& instrument) {
  if (py::isinstance<py::str>(instrument))
    return MakeInstrument(instrument.cast<std::string>(), 440);
  return instrument.cast<PyInstrument>();
}

py::object ContactPointPy(
    const py::object& instrument_arg,
    int string,
    const py::array_t<double, py::array::c_style | py::array::forcecast>& f0_hz,
    double open_tolerance_cents,
    double range_tolerance_cents,
    bool physical_correction) {
  const PyInstrument instrument = InstrumentFrom(instrument_arg);
  ContactOptions options;
  options.open_tolerance_cents = open_tolerance_cents;
  options.range_tolerance_cents = range_tolerance_cents;
  options.physical_correction = physical_correction;
  CheckValid(options.Validate());
  const size_t n = static_cast<size_t>(f0_hz.size());
  std::vector<Contact> contacts(n);
  const double* data = f0_hz.data();
  for (size_t i = 0; i < n; ++i) contacts[i] = ContactPoint(*instrument, string, data[i], options);
  auto fill = [&](auto field) {
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = contacts[i].*field;
    return v;
  };
  std::vector<int64_t> shape(f0_hz.shape(), f0_hz.shape() + f0_hz.ndim());
  py::dict out;
  if (f0_hz.ndim() == 0) {
    const Contact& c = contacts[0];
    out["kind"] = ContactKindName(c.kind);
    out["stopped"] = c.stopped();
    out["string"] = c.string;
    out["f0_hz"] = c.f0_hz;
    out["cents_from_open"] = c.cents_from_open;
    out["stop_from_bridge_mm"] = c.stop_from_bridge_mm;
    out["contact_from_bridge_mm"] = c.contact_from_bridge_mm;
    out["fraction_from_bridge"] = c.fraction_from_bridge;
    return std::move(out);
  }
  py::list kinds;
  std::vector<uint8_t> stopped(n);
  for (size_t i = 0; i < n; ++i) {
    kinds.append(ContactKindName(contacts[i].kind));
    stopped[i] = contacts[i].stopped();
  }
  out["kind"] =
      py::module_::import("numpy").attr("array")(kinds).attr("reshape")(f0_hz.attr("shape"));
  out["stopped"] = ToArray(std::move(stopped), shape).attr("view")("bool");
  out["string"] = string;
  out["f0_hz"] = ToArray(fill(&Contact::f0_hz), shape);
  out["cents_from_open"] = ToArray(fill(&Contact::cents_from_open), shape);
  out["stop_from_bridge_mm"] = ToArray(fill(&Contact::stop_from_bridge_mm), shape);
  out["contact_from_bridge_mm"] = ToArray(fill(&Contact::contact_from_bridge_mm), shape);
  out["fraction_from_bridge"] = ToArray(fill(&Contact::fraction_from_bridge), shape);
  return std::move(out);
}

void BindInstrument(py::module_& m) {
  py::class_<InstrumentModel, std::shared_ptr<InstrumentModel>>(
      m, "Instrument", "An instrument model")
      .def(py::init([](const std::string& name, double a4_hz) {
             return std::const_pointer_cast<InstrumentModel>(MakeInstrument(name, a4_hz));
           }),
           "name"_a = "cello",
           "a4_hz"_a = 440.0)
      .def_property_readonly("name", &InstrumentModel::name)
      .def_property_readonly("num_strings", &InstrumentModel::num_strings)
      .def_property_readonly("string_length_mm", &InstrumentModel::string_length_mm)
      .def_property_readonly("nut_spacing_mm", &InstrumentModel::nut_spacing_mm)
      .def_property_readonly("bridge_spacing_mm", &InstrumentModel::bridge_spacing_mm)
      .def("open_hz", &InstrumentModel::open_hz, "string"_a)
      .def("max_hz", &InstrumentModel::max_hz, "string"_a)
      .def("open_note_name", &InstrumentModel::open_note_name, "string"_a)
      .def("__repr__", [](const InstrumentModel& i) {
        return std::string("<arco.Instrument ") + i.name() + ">";
      });

  const ContactOptions c;
  m.def("contact_point",
        &ContactPointPy,
        "instrument"_a,
        "string"_a,
        "f0_hz"_a,
        py::kw_only(),
        "open_tolerance_cents"_a = c.open_tolerance_cents,
        "range_tolerance_cents"_a = c.range_tolerance_cents,
        "physical_correction"_a = c.physical_correction,
        R"(Where a finger stops `string` (1 = highest) to sound f0_hz (scalar or array).

instrument: an arco.Instrument or a name. Returns a dict: kind, stopped, string, f0_hz,
cents_from_open, stop_from_bridge_mm, contact_from_bridge_mm, fraction_from_bridge.)");
}

}  // namespace arco::python
