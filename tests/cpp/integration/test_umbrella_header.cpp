// The one header for library users compiles on its own and reaches every installed target.
#include "lidarloop/lidarloop.hpp"

#include <gtest/gtest.h>

namespace lidarloop {
namespace {

TEST(UmbrellaHeader, ReachesEveryTarget) {
    const core::DescriptorConfig descriptor;  // core, with core/ndt and core/scancontext
    EXPECT_NO_THROW(descriptor.Validate());
    EXPECT_NO_THROW(registration::VerificationConfig{}.Validate());  // registration
    EXPECT_NO_THROW(posegraph::PoseGraphConfig{}.Validate());        // posegraph
    EXPECT_GE(pipeline::MethodNames().size(), 4u);                   // pipeline
    EXPECT_EQ(eval::CondensedSize(4), 6u);                           // eval
    EXPECT_NO_THROW(sim::SimulationConfig{}.Validate());             // sim
    EXPECT_FALSE(io::DumpConfigYaml(io::RunConfig{}).empty());       // io
    const core::PointCloud cloud = {{1, 0, -1.5f}, {0, 2, 0.5f}, {3, 3, 2.0f}};
    const auto json = app::DescriptorJson(pipeline::ComputeDescriptor(cloud, descriptor));  // app
    EXPECT_EQ(json["method"], "range");
}

}  // namespace
}  // namespace lidarloop
