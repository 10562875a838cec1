// lidarloop.Error and its subclasses (docs/python.md, "Errors"). Each C++ error becomes the
// Python class of the same name with the same message; the classes also derive from the builtin
// that Python code would expect (ValueError for bad values, OSError for files, TypeError for a
// wrong dtype), so that `except ValueError` keeps working.
#include <exception>
#include <string>

#include "bindings.hpp"
#include "errors.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::python {
namespace {

namespace py = pybind11;

// The classes live as long as the interpreter; the module holds a reference too.
struct ErrorClasses {
    PyObject* error = nullptr;
    PyObject* config = nullptr;
    PyObject* format = nullptr;
    PyObject* empty_input = nullptr;
    PyObject* read = nullptr;
    PyObject* write = nullptr;
    PyObject* shape = nullptr;
    PyObject* dtype = nullptr;
    PyObject* non_finite = nullptr;
};

ErrorClasses& Classes() {
    static ErrorClasses classes;
    return classes;
}

PyObject* AddClass(py::module_& m, const char* name, const char* doc, py::tuple bases) {
    const std::string qualified = std::string("lidarloop.") + name;
    PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
    if (type == nullptr) throw py::error_already_set();
    m.add_object(name, py::handle(type));  // add_object takes a new reference
    return type;
}

PyObject* AddSubclass(py::module_& m, const char* name, const char* doc, PyObject* builtin) {
    return AddClass(m, name, doc, py::make_tuple(py::handle(Classes().error), py::handle(builtin)));
}

void Raise(PyObject* type, const std::exception& e) { PyErr_SetString(type, e.what()); }

// The library's write errors name the CLI's flag; a Python caller passes a keyword.
std::string InPythonTerms(std::string message) {
    static const std::string flag = "give --overwrite";
    static const std::string keyword = "pass overwrite=True";
    for (std::size_t at = message.find(flag); at != std::string::npos;
         at = message.find(flag, at + keyword.size())) {
        message.replace(at, flag.size(), keyword);
    }
    return message;
}

void RaiseReadError(const io::ReadError& e) {
    py::object error = py::reinterpret_borrow<py::object>(Classes().read)(e.what());
    error.attr("file") = e.file().string();
    PyErr_SetObject(Classes().read, error.ptr());
}

// Most derived first: ReadError is a core::Error too.
void Translate(std::exception_ptr error) {
    const ErrorClasses& classes = Classes();
    try {
        std::rethrow_exception(error);
    } catch (const io::ReadError& e) {
        RaiseReadError(e);
    } catch (const io::WriteError& e) {
        PyErr_SetString(classes.write, InPythonTerms(e.what()).c_str());
    } catch (const ShapeError& e) {
        Raise(classes.shape, e);
    } catch (const DtypeError& e) {
        Raise(classes.dtype, e);
    } catch (const NonFiniteError& e) {
        Raise(classes.non_finite, e);
    } catch (const core::ConfigError& e) {
        Raise(classes.config, e);
    } catch (const core::FormatError& e) {
        Raise(classes.format, e);
    } catch (const core::EmptyInputError& e) {
        Raise(classes.empty_input, e);
    } catch (const core::Error& e) {
        Raise(classes.error, e);
    }
}

}  // namespace

void BindErrors(py::module_& m) {
    ErrorClasses& c = Classes();
    c.error = AddClass(m, "Error", "Base of every error lidarloop raises on purpose.",
                       py::make_tuple(py::handle(PyExc_Exception)));
    c.config = AddSubclass(m, "ConfigError",
                           "A configuration value is out of its valid range or inconsistent.",
                           PyExc_ValueError);
    c.format = AddSubclass(m, "FormatError",
                           "Encoded data (a saved database, ...) is damaged or not what it claims.",
                           PyExc_ValueError);
    c.empty_input = AddSubclass(
        m, "EmptyInputError",
        "The input holds no usable data (empty scan, every point out of range).", PyExc_ValueError);
    c.read = AddSubclass(m, "ReadError",
                         "A file could not be read or parsed; `.file` is its path (str).",
                         PyExc_OSError);
    c.write = AddSubclass(m, "WriteError", "A file could not be written.", PyExc_OSError);
    c.shape = AddSubclass(m, "ShapeError",
                          "An array of the wrong shape, e.g. points that are not (N, 3) or (N, 4).",
                          PyExc_ValueError);
    c.dtype =
        AddSubclass(m, "DtypeError", "An argument that is not a NumPy array of float32 or float64.",
                    PyExc_TypeError);
    c.non_finite =
        AddSubclass(m, "NonFiniteError", "A NaN or infinite value where finite values are needed.",
                    PyExc_ValueError);
    py::register_exception_translator(&Translate);
}

}  // namespace lidarloop::python
