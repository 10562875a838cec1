#include "lidarloop/core/scancontext/scancontext_config.hpp"

#include <sstream>
#include <string>

#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

// ConfigError "scancontext.<field> must be in [low, high], got value" unless it is; a NaN fails.
template <typename T>
void RequireIn(T value, T low, T high, const char* field) {
    if (value >= low && value <= high) return;
    std::ostringstream message;
    message << "scancontext." << field << " must be in [" << low << ", " << high << "], got "
            << value;
    throw ConfigError(message.str());
}

}  // namespace

void ScanContextConfig::Validate() const {
    RequireIn(rings, 1, 200, "rings");
    // At least 6 sectors: a sector spans less than 180 degrees, which the exact sector test of
    // the binning relies on.
    RequireIn(sectors, 6, 720, "sectors");
    RequireIn(max_range_m, 0.1, 10'000.0, "max_range_m");
    RequireIn(sensor_height_m, -1'000.0, 1'000.0, "sensor_height_m");
    RequireIn(ring_key_candidates, 0, 1'000'000, "ring_key_candidates");
}

}  // namespace lidarloop::core
