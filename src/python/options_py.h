// Python classes generated from the library's option descriptions (util/options.h): one template for every
// described struct, so the attributes, their docs, units, ranges and checks are the ones the CLI and the JSON
// use — nothing is copied by hand.
//
//   BindStruct<FillOptions>(m);   // lidarshop.FillOptions(patch_radius=6, method="laplace")
//
// gives a class named after StructInfo::name with
//   - one attribute per field and per alias (an older flat key of a nested field: FillOptions.patch_radius
//     is FillOptions.inpaint.patch_radius); numbers, bools, strings, number lists as Python values; enums as their names
//     ("laplace"); nested structs as nested objects (changing `o.poisson.tolerance` changes `o`);
//     assignment checks the value (kind and range) and raises lidarshop.OptionsError (a ValueError) with the
//     library's message, naming the key;
//   - keyword construction and from_dict() (unknown keys, bad values and cross-field checks raise the same
//     way), to_dict() (every field, JSON order; an exact round trip), validate(), copy(), ==, repr and pickle;
//   - docstrings built from the descriptions (doc, unit, range, choices, default).
// Result structs (FillResult, ...) use the same template with `read_only`: their attributes cannot be set and
// the hand-written parts (images, scans) are added to the returned py::class_.
#pragma once

#include <algorithm>
#include <functional>
#include <map>
#include <string>

#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // fields (a list of names) in every instantiation

#include "convert.h"
#include "lidarshop/util/options.h"

namespace lidarshop::python {

namespace py = pybind11;

// How to make the Python object of a described struct from its address (nested attributes), by description.
using NestedCaster = std::function<py::object(void* object, py::handle parent)>;
std::map<const StructInfo*, NestedCaster>& NestedCasters();

// "patch half-width [cells] in [1, 32], default 4"; enums list their names.
std::string FieldDoc(const FieldInfo& field, const nlohmann::ordered_json& default_value);
// The class docstring: the struct's doc and one line per field.
std::string StructDoc(const StructInfo& info, const void* defaults);
// "FillOptions(method='gradient', patch_radius=4, ...)".
std::string StructRepr(const StructInfo& info, const void* object);
// Sets one field from a Python value (nested structs: an options object or a dict), checking it first;
// throws OptionsFieldError naming the key.
void SetField(const StructInfo& info, const FieldInfo& field, void* object, const py::handle& value);
// The Python value of one field (nested structs: the nested object, kept alive by `parent`).
py::object GetField(const FieldInfo& field, void* object, py::handle parent);
// StructFromJson of a Python dict (or keyword arguments).
void ApplyDict(const StructInfo& info, const py::handle& dict, void* object);

template <class S>
py::class_<S> BindStruct(py::module_& m, bool read_only = false) {
  const StructInfo& info = InfoOf<S>();
  const S defaults{};
  py::class_<S> cls(m, info.name.c_str());
  cls.doc() = StructDoc(info, &defaults);
  NestedCasters()[&info] = [](void* object, py::handle parent) {
    return py::cast(static_cast<S*>(object), py::return_value_policy::reference_internal, parent);
  };
  if (!read_only) {
    cls.def(py::init([](const py::kwargs& kwargs) {
              S object{};
              ApplyDict(InfoOf<S>(), kwargs, &object);
              return object;
            }),
            "Keyword construction: every keyword is a field (see the class doc); the others keep their "
            "defaults. Raises OptionsError for an unknown key or a bad value.");
  }
  for (const FieldInfo& field : info.fields) {
    const FieldInfo* field_pointer = &field;
    auto getter = [field_pointer](py::object self) {
      return GetField(*field_pointer, self.cast<S*>(), self);
    };
    const std::string doc = FieldDoc(field, field.get(&defaults));
    if (read_only) {
      cls.def_property_readonly(field.key.c_str(), getter, doc.c_str());
    } else {
      cls.def_property(
          field.key.c_str(), getter,
          [field_pointer](S& self, const py::object& value) {
            SetField(InfoOf<S>(), *field_pointer, &self, value);
          },
          doc.c_str());
    }
  }
  // An alias (an older flat key of a nested field, util/options.h) reads and sets that field; it is not in
  // `fields` nor in to_dict().
  for (const FieldInfo& alias : info.aliases) {
    const FieldInfo* alias_pointer = &alias;
    auto getter = [alias_pointer](py::object self) {
      return GetField(*alias_pointer, self.cast<S*>(), self);
    };
    const std::string doc =
        fmt::format("Alias of {}: {}", alias.alias_of, FieldDoc(alias, alias.get(&defaults)));
    if (read_only) {
      cls.def_property_readonly(alias.key.c_str(), getter, doc.c_str());
    } else {
      cls.def_property(
          alias.key.c_str(), getter,
          [alias_pointer](S& self, const py::object& value) {
            SetField(InfoOf<S>(), *alias_pointer, &self, value);
          },
          doc.c_str());
    }
  }
  // A misspelt attribute raises AttributeError with the closest field (pybind11 would say only "no attribute").
  cls.def("__setattr__", [](py::object self, const std::string& name, py::object value) {
    if (name.empty() || name[0] != '_') {
      std::vector<std::string> keys = InfoOf<S>().Keys();
      for (const std::string& alias : InfoOf<S>().AliasKeys()) keys.push_back(alias);
      if (std::find(keys.begin(), keys.end(), name) == keys.end()) {
        const std::string closest = ClosestMatch(name, keys);
        throw py::attribute_error(
            fmt::format("{} has no field '{}'{}", InfoOf<S>().name, name,
                        closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest)));
      }
    }
    py::module_::import("builtins").attr("object").attr("__setattr__")(self, name, value);
  });
  cls.def(
      "to_dict", [](const S& self) { return FromJsonValue(ToJson(self)); },
      "Every field as a dict (JSON order, enums as names, nested structs as dicts): the JSON form of the "
      "CLI's --options files.");
  cls.def("__repr__", [](const S& self) { return StructRepr(InfoOf<S>(), &self); });
  cls.def("__eq__", [](const S& self, const py::object& other) {
    if (!py::isinstance<S>(other)) return false;
    return ToJson(self) == ToJson(other.cast<const S&>());
  });
  cls.def(
      "copy", [](const S& self) { return S(self); }, "An independent copy.");
  cls.def("__copy__", [](const S& self) { return S(self); });
  cls.def("__deepcopy__", [](const S& self, py::dict) { return S(self); });
  cls.def_property_readonly_static(
      "fields", [](py::object) { return py::cast(InfoOf<S>().Keys()); }, "The field names, in order.");
  if (!read_only) {
    cls.def_static(
        "from_dict",
        [](const py::dict& dict) {
          S object{};
          ApplyDict(InfoOf<S>(), dict, &object);
          return object;
        },
        py::arg("dict"),
        "The defaults with the fields of `dict` applied (the JSON form, as to_dict gives). Raises "
        "OptionsError "
        "naming the key path for an unknown key or a bad value.");
    cls.def(
        "validate", [](const S& self) { Validate(self); },
        "Checks every field and the cross-field checks; raises OptionsError naming the first bad key.");
    cls.def(py::pickle([](const S& self) { return FromJsonValue(ToJson(self)); },
                       [](const py::object& state) {
                         S object{};
                         ApplyDict(InfoOf<S>(), state, &object);
                         return object;
                       }));
  }
  return cls;
}

}  // namespace lidarshop::python
