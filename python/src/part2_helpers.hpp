#pragma once

// Helpers of the part-2 bindings (registration, posegraph, eval, sim, app): arrays of
// transforms, config objects built from keyword arguments, Python progress callbacks. They
// build on conversions.hpp and, like it, run with the GIL held unless said otherwise.

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "conversions.hpp"
#include "lidarloop/app/progress.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::python {

/// Transforms (each a T_world_sensor or the like) from an (N, 4, 4) float32/float64 array; the
/// errors of TransformFromArray, naming `what`[i].
inline std::vector<core::Transform> TransformsFromArray(const py::handle& object,
                                                        const std::string& what) {
    CheckFloatArray(object, what);
    const auto array = py::array_t<double, py::array::forcecast>::ensure(object);
    if (array.ndim() != 3 || array.shape(1) != 4 || array.shape(2) != 4) {
        throw ShapeError(what + " must have shape (N, 4, 4), got " +
                         py::str(object.attr("shape")).cast<std::string>());
    }
    std::vector<core::Transform> transforms;
    transforms.reserve(static_cast<std::size_t>(array.shape(0)));
    for (py::ssize_t i = 0; i < array.shape(0); ++i) {
        transforms.push_back(
            TransformFromArray(array[py::make_tuple(i)], what + "[" + std::to_string(i) + "]"));
    }
    return transforms;
}

/// An (N, 4, 4) float64 array of `transforms` (a copy).
inline py::array_t<double> TransformsToArray(const std::vector<core::Transform>& transforms) {
    const auto n = static_cast<py::ssize_t>(transforms.size());
    py::array_t<double> array({n, py::ssize_t{4}, py::ssize_t{4}});
    auto out = array.mutable_unchecked<3>();
    for (py::ssize_t i = 0; i < n; ++i) {
        const Eigen::Matrix4d& m = transforms[static_cast<std::size_t>(i)].matrix();
        for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) out(i, r, c) = m(r, c);
        }
    }
    return array;
}

/// A 1-D float64 array from a sequence of numbers (list, tuple or array; one copy). ShapeError
/// unless 1-D.
inline std::vector<double> DoublesFrom(const py::handle& object, const std::string& what) {
    const auto array = py::array_t<double, py::array::forcecast>::ensure(object);
    if (!array || array.ndim() != 1) {
        throw ShapeError(what + " must be a 1-D sequence of numbers");
    }
    return {array.data(), array.data() + array.shape(0)};
}

/// Sets the attributes `kwargs` names on a default-constructed T (bound as `object`'s class),
/// so that the defaults stay those of the C++ struct. Unknown names raise AttributeError (the
/// bound classes have no __dict__), naming the key.
template <typename T>
T FromKeywords(const py::kwargs& kwargs) {
    py::object object = py::cast(T{});
    for (const auto& [key, value] : kwargs) {
        const std::string name = py::str(key).cast<std::string>();
        if (!py::hasattr(object, name.c_str()) || name.starts_with("_")) {
            throw py::type_error(
                py::str(py::type::of(object).attr("__name__")).cast<std::string>() +
                " has no field '" + name + "'");
        }
        object.attr(name.c_str()) = value;
    }
    return object.cast<T>();
}

/// A Python callable as an app::Progress, called (GIL acquired) from worker threads as the
/// run proceeds. The first exception it raises is kept (and the callable no longer called), so
/// that no exception crosses the C++ threads; Rethrow() raises it after the run, with the GIL.
class PythonProgress {
public:
    explicit PythonProgress(py::object callback)
        : state_(std::make_shared<State>(State{std::move(callback), {}})) {}

    /// Empty when there is no callable (None).
    app::Progress Callback() const {
        if (state_->callback.is_none()) return {};
        return [state = state_](const std::string& stage, std::size_t done, std::size_t total) {
            py::gil_scoped_acquire gil;
            if (state->error) return;
            try {
                state->callback(stage, done, total);
            } catch (py::error_already_set& e) {
                state->error = std::make_unique<py::error_already_set>(std::move(e));
            }
        };
    }
    bool Failed() const { return state_->error != nullptr; }
    /// Raises the callable's exception, if it raised one (GIL held).
    void Rethrow() const {
        if (state_->error) {
            py::error_already_set error = std::move(*state_->error);
            state_->error.reset();
            throw error;
        }
    }

private:
    struct State {
        py::object callback;
        std::unique_ptr<py::error_already_set> error;
    };
    // Copies of Callback() share the state; the last owner is this object, destroyed by the
    // binding with the GIL held (so the Python objects are released safely).
    std::shared_ptr<State> state_;
};

}  // namespace lidarloop::python
