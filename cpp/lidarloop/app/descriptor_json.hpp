#pragma once

#include <nlohmann/json.hpp>

#include "lidarloop/core/descriptor.hpp"

namespace lidarloop::app {

/// The descriptor as `lidarloop describe` prints it: method, value range and bins of a
/// histogram; every rotation candidate's F, cell count and R_aligned_sensor of an NDT set; the
/// bins (rings x sectors) and ring key of a Scan Context; the points used and skipped (keys in
/// docs/cli.md). A method whose descriptor is none of core::Histogram, core::NdtDescriptorSet,
/// core::ScanContext shows its name only.
nlohmann::json DescriptorJson(const core::Descriptor& descriptor);

}  // namespace lidarloop::app
