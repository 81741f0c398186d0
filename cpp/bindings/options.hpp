// The one way option structs cross the binding: OptionClass<C> binds a core option struct with a
// "name : type\n    description" docstring per field, a keyword constructor (an unknown keyword is a
// ValueError naming it), __repr__, copies, `fields` (the field names, in order) and `validate()`,
// the core's check of the struct (std::invalid_argument naming the field becomes ValueError).
// Results bound read-only use `readonly` with the same docstring form.
#pragma once

#include <pybind11/pybind11.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

namespace bayesgrasp::bind {

namespace py = pybind11;

inline std::string field_doc(const char* name, const char* type, const char* doc) {
  return std::string(name) + " : " + type + "\n    " + doc;
}

// repr of one field; "..." if its type is not bound (yet).
inline std::string field_repr(const py::object& self, const std::string& name) {
  try {
    return py::repr(self.attr(name.c_str()));
  } catch (const py::error_already_set&) {
    return "...";
  } catch (const py::cast_error&) {
    return "...";
  }
}

template <typename C>
class OptionClass {
 public:
  OptionClass(py::handle scope, const char* name, const char* doc) : cls_(scope, name, doc), name_(name) {}

  /// A read-write field; `member` may belong to a base of C.
  template <typename B, typename T>
  OptionClass& field(const char* name, T B::*member, const char* type, const char* doc) {
    cls_.def_readwrite(name, member, field_doc(name, type, doc).c_str());
    fields_->push_back(name);
    return *this;
  }

  /// A read-write field converted on the way (an enum as its name, say).
  template <typename Get, typename Set>
  OptionClass& property(const char* name, Get get, Set set, const char* type, const char* doc) {
    cls_.def_property(name, get, set, field_doc(name, type, doc).c_str());
    fields_->push_back(name);
    return *this;
  }

  /// Binds validate() to the core's check of the struct (a callable taking const C&).
  template <typename Check>
  OptionClass& validator(Check check) {
    cls_.def("validate", [check](const C& c) { check(c); }, "Raises ValueError naming the first bad field.");
    return *this;
  }

  /// Adds the constructor, __repr__, copies and `fields`; call once, after the last field.
  py::class_<C>& finish() {
    const auto fields = fields_;
    const std::string cname = name_;
    py::tuple names(fields->size());
    for (std::size_t i = 0; i < fields->size(); ++i) names[i] = py::str((*fields)[i]);
    cls_.attr("fields") = names;
    cls_.def(py::init([fields, cname](const py::kwargs& kw) {
               py::object self = py::cast(C{});
               for (const auto& item : kw) {
                 const std::string key = py::str(item.first);
                 if (std::find(fields->begin(), fields->end(), key) == fields->end())
                   throw py::value_error(key + ": not a field of " + cname);
                 self.attr(key.c_str()) = item.second;
               }
               return self.cast<C>();
             }),
             ("Defaults, with any field given by keyword: " + cname + "(name=value, ...).").c_str())
        .def("__repr__",
             [fields, cname](const py::object& self) {
               std::string s = cname + "(";
               for (std::size_t i = 0; i < fields->size(); ++i)
                 s += (i ? ", " : "") + (*fields)[i] + "=" + field_repr(self, (*fields)[i]);
               return s + ")";
             })
        .def("__copy__", [](const C& c) { return C(c); })
        .def("__deepcopy__", [](const C& c, const py::object&) { return C(c); }, py::arg("memo"));
    return cls_;
  }

  py::class_<C>& cls() { return cls_; }

 private:
  py::class_<C> cls_;
  std::string name_;
  std::shared_ptr<std::vector<std::string>> fields_ = std::make_shared<std::vector<std::string>>();
};

/// A read-only field of a bound result struct, with the same docstring form as OptionClass's.
template <typename C, typename B, typename T>
void readonly(py::class_<C>& cls, const char* name, T B::*member, const char* type, const char* doc) {
  cls.def_readonly(name, member, field_doc(name, type, doc).c_str());
}

}  // namespace bayesgrasp::bind
