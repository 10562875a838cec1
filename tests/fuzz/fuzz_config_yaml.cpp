// libFuzzer harness: io::ApplyConfigYaml on any text, as a --config file and as a saved
// database's embedded config.
#include <cstddef>
#include <cstdint>

#include <string>

#include "fuzz_input.hpp"
#include "lidarloop/io/config_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace lidarloop;
    const std::string text(reinterpret_cast<const char*>(data), size);
    for (const io::LegacyKeys legacy : {io::LegacyKeys::kExplain, io::LegacyKeys::kMigrate}) {
        io::RunConfig config;
        fuzz::ExpectResultOrReadError(
            "fuzz.yaml", [&] { io::ApplyConfigYaml(text, "fuzz.yaml", config, legacy); });
    }
    return 0;
}
