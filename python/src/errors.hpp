#pragma once

#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::python {

// Errors of the Python layer only: arrays handed to lidarloop that it cannot take. They derive
// from core::Error, so that one translator (bind_errors.cpp) turns every lidarloop error into a
// lidarloop.Error, these into lidarloop.ShapeError, DtypeError and NonFiniteError.

/// An array of the wrong shape, e.g. points that are not (N, 3) or (N, 4).
class ShapeError : public core::Error {
public:
    using core::Error::Error;
};

/// An argument that is not a NumPy array of a dtype lidarloop takes (float32 or float64).
class DtypeError : public core::Error {
public:
    using core::Error::Error;
};

/// A NaN or infinite value where lidarloop needs finite ones.
class NonFiniteError : public core::Error {
public:
    using core::Error::Error;
};

}  // namespace lidarloop::python
