#pragma once

// The run options of detect, evaluate and optimise as Python keywords, from their one
// declaration (app/run_options.hpp, docs/options.md): converted, applied and recorded for
// run.json by the table, as cli/run_options.cpp does for the flags.

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "lidarloop/app/run_options.hpp"

namespace lidarloop::python {

/// A keyword's value as its option's type (app/run_options.hpp), NumPy scalars as the numbers
/// they hold; TypeError naming it otherwise, also for an int beyond the option's int range.
inline app::RunOptionValue RunValueOf(const app::RunOption& option, const py::handle& value) {
    using T = app::RunOptionType;
    const py::module_ numpy = py::module_::import("numpy");
    const bool is_bool =
        py::isinstance<py::bool_>(value) || py::isinstance(value, numpy.attr("bool_"));
    const bool is_int = !is_bool && (py::isinstance<py::int_>(value) ||
                                     py::isinstance(value, numpy.attr("integer")));
    const bool is_float =
        py::isinstance<py::float_>(value) || py::isinstance(value, numpy.attr("floating"));
    try {
        switch (option.type) {
            case T::kInt:
                if (is_int) return py::int_(py::reinterpret_borrow<py::object>(value)).cast<int>();
                break;
            case T::kNumber:
                if (is_int || is_float) return value.cast<double>();
                break;
            case T::kName:
                if (py::isinstance<py::str>(value)) return value.cast<std::string>();
                break;
            case T::kNumbers:
                if (!is_bool && !py::isinstance<py::str>(value) &&
                    py::isinstance<py::sequence>(value))
                    return value.cast<std::vector<double>>();
                break;
            case T::kSwitch:
            case T::kSwitchOff:
                if (is_bool) return value.cast<bool>();
                break;
        }
    } catch (const py::cast_error&) {
        // An int too large for the option, or a list with a non-number: said as below.
    }
    static constexpr const char* kKinds[] = {"an int (32-bit)",   "a number", "a str",
                                             "a list of numbers", "a bool",   "a bool"};
    throw py::type_error(std::string(option.keyword) + " must be " +
                         kKinds[static_cast<int>(option.type)] + ", got " +
                         py::repr(value).cast<std::string>());
}

/// The run options of `command` among `keywords` (app/run_options.hpp: what the flags of the
/// same command set), applied in declaration order; None keeps the config's value. Each one
/// given is added to `given`, the call text of run.json. TypeError for any other keyword, as
/// Python raises it.
inline void ApplyRunKeywords(app::RunCommand command, const py::kwargs& keywords,
                             const app::RunTargets& targets, py::dict& given) {
    const std::vector<const app::RunOption*> options = app::RunOptionsOf(command);
    for (const auto& [key, value] : keywords) {
        const auto name = key.cast<std::string>();
        const bool known = std::any_of(options.begin(), options.end(),
                                       [&](const auto* o) { return o->keyword == name; });
        if (!known) {
            throw py::type_error(std::string(app::NameOf(command)) +
                                 "() got an unexpected keyword argument '" + name + "'");
        }
    }
    // First the config as given, so that an error of its own is not a keyword's.
    targets.config->Validate();
    for (const app::RunOption* option : options) {
        const std::string keyword(option->keyword);
        if (!keywords.contains(keyword) || keywords[keyword.c_str()].is_none()) continue;
        const py::object value = keywords[keyword.c_str()];
        app::ApplyRunOption(*option, RunValueOf(*option, value), targets, /*by_keyword=*/true);
        given[keyword.c_str()] = value;
    }
}

/// The docstring of a run function: `text`, then its run options, each with its help.
inline const char* RunDoc(app::RunCommand command, const std::string& text) {
    static std::vector<std::unique_ptr<std::string>> docs;  // pybind11 keeps the pointer
    std::string doc =
        text +
        "\n\nRun options (keywords; None keeps the config's value; the flags of `lidarloop " +
        std::string(app::NameOf(command)) + "`):";
    for (const app::RunOption* option : app::RunOptionsOf(command)) {
        doc += "\n    " + std::string(option->keyword) + " (" + std::string(option->flag) +
               "): " + std::string(option->help);
    }
    docs.push_back(std::make_unique<std::string>(std::move(doc)));
    return docs.back()->c_str();
}

/// lidarloop.run_options(command): the declaration, for the docs and the tests.
inline void BindRunOptions(py::module_& m) {
    m.def(
        "run_options",
        [](const std::string& command) {
            static constexpr const char* kTypes[] = {"int",         "float", "str",
                                                     "list[float]", "bool",  "bool"};
            py::list list;
            for (const app::RunOption* o : app::RunOptionsOf(app::RunCommandOf(command))) {
                py::dict d;
                d["keyword"] = std::string(o->keyword);
                d["flag"] = std::string(o->flag);
                d["value_name"] = std::string(o->value_name);
                d["type"] = kTypes[static_cast<int>(o->type)];
                d["help"] = std::string(o->help);
                d["sets"] = std::string(o->sets);
                d["default"] = o->default_text();
                list.append(d);
            }
            return list;
        },
        py::arg("command"),
        "The run options of detect, evaluate, optimise or bench, as declared once "
        "(app/run_options.hpp): 'keyword', 'flag', 'value_name', 'type', 'help', 'sets', "
        "'default'. detect(), evaluate() and optimise() take them as keywords.");
}

}  // namespace lidarloop::python
