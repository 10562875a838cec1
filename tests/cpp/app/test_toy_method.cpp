// A further descriptor registered through the public interface only, then run end to end: online
// and offline detection, a saved map and localisation against it, and both papers' evaluation.
// The method: the share of a scan's points in each range ring (a histogram of point counts per
// ring), compared by the L1 distance of the shares. Its two parameters are declared once
// (RingParameters::Declare) and reach the YAML config, dump-config, validation and the keywords
// without a line anywhere else (docs/options.md).
#include <cmath>
#include <fstream>
#include <optional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app_test_utils.hpp"
#include "lidarloop/app/descriptor_json.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/parameters.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

using Shares = std::vector<double>;

// The method's parameters: YAML section `rings`, as the method is named.
struct RingParameters {
    int ring_count = 16;
    double ring_width_m = 5.0;

    template <typename Self, typename Visit>
    static void Declare(Self& c, Visit&& visit) {
        visit(c.ring_count,
              {"ring_count", "rings counted; the last takes all farther points", "", 1, 64});
        visit(c.ring_width_m, {"ring_width_m", "width of a ring", "m", 0.1, 100.0});
    }
    void Validate() const { core::CheckDeclaredRanges("rings", *this); }
    bool operator==(const RingParameters&) const = default;
};

double L1(const Shares& a, const Shares& b) {
    double sum = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) sum += std::abs(a[k] - b[k]);
    return sum;
}

// The store: the shares of every scan as they are.
class RingStore : public pipeline::DescriptorStore {
public:
    explicit RingStore(int rings) : rings_(static_cast<std::size_t>(rings)) {}
    struct Query : pipeline::PreparedQuery {
        Shares shares;
    };
    std::unique_ptr<DescriptorStore> Clone() const override {
        return std::make_unique<RingStore>(*this);
    }
    void Add(const core::Descriptor& d) override { rows_.push_back(d.As<Shares>()); }
    void AddMissing() override { rows_.emplace_back(rings_, 0.0); }
    double Distance(std::size_t i, std::size_t j) const override { return L1(rows_[i], rows_[j]); }
    std::unique_ptr<pipeline::PreparedQuery> Prepare(const core::Descriptor& d) const override {
        auto query = std::make_unique<Query>();
        query->shares = d.As<Shares>();
        return query;
    }
    std::unique_ptr<pipeline::PreparedQuery> PrepareStored(std::size_t i) const override {
        auto query = std::make_unique<Query>();
        query->shares = rows_[i];
        return query;
    }
    double Distance(const pipeline::PreparedQuery& q, std::size_t j) const override {
        return L1(static_cast<const Query&>(q).shares, rows_[j]);
    }
    void Encode(std::size_t i, core::ByteWriter& out) const override {
        out.PutArray(rows_[i].data(), rows_[i].size());
    }
    void Decode(core::ByteReader& in, bool) override {
        Shares shares(rings_);
        in.GetArray(shares.data(), shares.size(), "ring shares");
        rows_.push_back(std::move(shares));
    }

private:
    std::size_t rings_;
    std::vector<Shares> rows_;
};

class RingCounts : public pipeline::DescriptorMethod {
public:
    RingCounts() : DescriptorMethod(core::Method("rings")) {}
    core::Descriptor Describe(const core::PointCloud& cloud,
                              const core::DescriptorConfig& config) const override {
        const RingParameters& p = ParametersOf(config);
        const int rings = p.ring_count;
        Shares shares(static_cast<std::size_t>(rings), 0.0);
        double counted = 0.0;
        for (const Eigen::Vector3f& point : cloud) {
            if (!point.allFinite()) continue;
            const auto ring = static_cast<int>(point.head<2>().norm() / p.ring_width_m);
            shares[static_cast<std::size_t>(std::min(ring, rings - 1))] += 1.0;
            counted += 1.0;
        }
        if (counted == 0.0) throw core::EmptyInputError("no finite point");
        for (double& share : shares) share /= counted;
        return {method(), shares};
    }
    double Distance(const core::Descriptor& a, const core::Descriptor& b) const override {
        return L1(a.As<Shares>(), b.As<Shares>());
    }
    std::unique_ptr<pipeline::DescriptorStore> MakeStore(
        const core::DescriptorConfig& config) const override {
        return std::make_unique<RingStore>(ParametersOf(config).ring_count);
    }
    double DefaultThreshold() const override { return 0.1; }
    std::optional<core::MethodParameters> DefaultParameters() const override {
        return core::MethodParameters(name(), RingParameters{});
    }
    static const RingParameters& ParametersOf(const core::DescriptorConfig& config) {
        return config.methods.Get<RingParameters>("rings");
    }
};

// The one registration line, once per process.
const core::Method kRingsMethod = [] {
    pipeline::RegisterMethod(std::make_shared<RingCounts>());
    return pipeline::ParseMethod("rings");
}();

class ToyMethod : public ::testing::Test {
protected:
    void SetUp() override { dataset_.emplace(test::SmallSequence(dir_ / "sequence")); }
    io::RunConfig RingsConfig() const {
        io::RunConfig config;
        io::ApplyConfigYaml("method: rings\ndetection:\n  min_gap: 10\n  min_path_m: 0\n",
                            "rings.yaml", config);
        // The method interface is under test, not registration (slow under the sanitizers).
        config.detection.verify = false;
        return config;
    }

    test::TempDir dir_;
    std::optional<io::Dataset> dataset_;
};

TEST_F(ToyMethod, DetectsLoopsExactlyAsComparingEveryEarlierScan) {
    app::DetectRequest request{RingsConfig(), false, {}, dir_ / "detect", {}, {}, {}};
    request.config.detection.verify = false;  // the descriptor's own decision
    const app::DetectOutcome outcome = app::RunDetect(*dataset_, request);
    ASSERT_EQ(outcome.queries.size(), dataset_->size());
    EXPECT_EQ(outcome.threshold, 0.1);
    std::vector<Shares> shares;
    for (std::size_t i = 0; i < dataset_->size(); ++i)
        shares.push_back(RingCounts().Describe(dataset_->LoadScan(i), {}).As<Shares>());
    std::size_t accepted = 0;
    for (std::size_t i = 11; i < dataset_->size(); ++i) {
        const pipeline::LoopQuery& q = outcome.queries[i];
        ASSERT_TRUE(q.has_match()) << i;
        std::size_t best = 0;
        for (std::size_t j = 1; j + 10 < i; ++j) {
            if (L1(shares[i], shares[j]) < L1(shares[i], shares[best])) best = j;
        }
        EXPECT_EQ(q.candidates.front().index, best) << i;
        EXPECT_NEAR(q.candidates.front().distance, L1(shares[i], shares[best]), 1e-6) << i;
        accepted += L1(shares[i], shares[best]) <= 0.1 ? 1 : 0;
    }
    EXPECT_EQ(outcome.accepted, accepted);
    EXPECT_TRUE(std::filesystem::exists(request.out / "database.lldb"));
}

TEST_F(ToyMethod, ASavedMapLoadsAndLocalisesEveryScanAtItself) {
    app::DetectRequest request{RingsConfig(), false, {}, dir_ / "detect", {}, {}, {}};
    app::RunDetect(*dataset_, request);
    request.out = dir_ / "localise";
    const app::DetectOutcome outcome =
        app::RunLocalise(*dataset_, app::LoadMap(dir_ / "detect" / "database.lldb"), request);
    EXPECT_EQ(outcome.accepted, dataset_->size());
    for (const pipeline::LoopQuery& q : outcome.queries) {
        ASSERT_TRUE(q.has_match()) << q.query;
        EXPECT_EQ(q.candidates.front().distance, 0.0) << q.query;
    }
}

TEST_F(ToyMethod, IsEvaluatedBesideThePapersMethods) {
    app::EvaluationRequest request;
    request.config = RingsConfig();
    request.methods = {kRingsMethod, core::Method::kRange};
    request.out = dir_ / "evaluation";
    const app::EvaluationOutcome outcome = app::RunEvaluation(*dataset_, request);
    ASSERT_EQ(outcome.methods.size(), 2U);
    const app::MethodEvaluation& rings = outcome.methods[0];
    EXPECT_EQ(rings.name, "rings");
    EXPECT_EQ(rings.default_threshold, 0.1);
    EXPECT_EQ(rings.pairwise.pairs, outcome.methods[1].pairwise.pairs);
    EXPECT_GT(rings.pairwise.positives, 0U);
    std::ifstream metrics_file(request.out / "metrics.json");
    const nlohmann::json metrics = nlohmann::json::parse(metrics_file);
    EXPECT_TRUE(metrics["methods"].contains("rings"));
    EXPECT_NE(test::ReadFile(request.out / "report.md").find("| rings |"), std::string::npos);
}

TEST_F(ToyMethod, AMapOfAMethodThisProcessLacksIsAClearError) {
    app::DetectRequest request{RingsConfig(), false, {}, dir_ / "detect", {}, {}, {}};
    app::RunDetect(*dataset_, request);
    std::string saved = test::ReadFile(dir_ / "detect" / "database.lldb");
    const auto at = saved.find("method: rings");
    ASSERT_NE(at, std::string::npos);
    saved.replace(at, 13, "method: rongs");  // as if saved by a program with another method
    test::WriteFile(dir_ / "other.lldb", saved);
    try {
        app::LoadMap(dir_ / "other.lldb");
        FAIL() << "loaded a database of an unknown method";
    } catch (const io::ReadError& e) {
        EXPECT_NE(std::string(e.what()).find("unknown method 'rongs'"), std::string::npos)
            << e.what();
    }
}

TEST_F(ToyMethod, IsNamedInConfigsAndShownByName) {
    EXPECT_NE(io::DumpConfigYaml({}).find("height | range | ndt | scancontext | rings"),
              std::string::npos);
    const core::Descriptor d =
        pipeline::ComputeDescriptor(dataset_->LoadScan(0), RingsConfig().descriptor);
    EXPECT_EQ(app::DescriptorJson(d), (nlohmann::json{{"method", "rings"}}));
}

}  // namespace
}  // namespace lidarloop

namespace lidarloop {
namespace {

std::string ConfigErrorOf(const std::string& yaml) {
    io::RunConfig config;
    try {
        io::ApplyConfigYaml(yaml, "rings.yaml", config);
    } catch (const io::ReadError& e) {
        return e.what();
    }
    return "";
}

// The declaration is all the method wrote: its YAML section, dump-config, validation, equality
// with defaults and the keywords (Python sends describe()'s as this JSON) follow from it.
TEST_F(ToyMethod, DeclaresItsParametersOnceForTheConfigAndTheKeywords) {
    const std::string dump = io::DumpConfigYaml({});
    EXPECT_NE(dump.find("rings:\n  ring_count: 16  # rings counted; the last takes all farther "
                        "points\n  ring_width_m: 5  # width of a ring\n"),
              std::string::npos)
        << dump;
    io::RunConfig config = RingsConfig();
    io::ApplyConfigYaml("rings:\n  ring_width_m: 4\n", "rings.yaml", config);
    EXPECT_EQ(RingCounts::ParametersOf(config.descriptor).ring_width_m, 4.0);
    EXPECT_NE(io::DumpConfigYaml(config).find("  ring_width_m: 4  #"), std::string::npos);
    io::ApplyConfigYaml(R"({"rings": {"ring_count": 8}})", "keywords", config);
    const core::Descriptor d =
        pipeline::ComputeDescriptor(dataset_->LoadScan(0), config.descriptor);
    EXPECT_EQ(d.As<Shares>().size(), 8u);
    EXPECT_NE(ConfigErrorOf("rings:\n  ring_cuont: 3\n")
                  .find("key 'rings.ring_cuont': unknown key (valid here: ring_count, "
                        "ring_width_m)"),
              std::string::npos)
        << ConfigErrorOf("rings:\n  ring_cuont: 3\n");
    EXPECT_NE(ConfigErrorOf("rings:\n  ring_count: 0\n")
                  .find("rings.ring_count must be in [1, 64], got 0"),
              std::string::npos)
        << ConfigErrorOf("rings:\n  ring_count: 0\n");
    EXPECT_NE(ConfigErrorOf("rings:\n  ring_width_m: wide\n").find("expected a number"),
              std::string::npos);
    // Its defaults written out and read back equal a config that never named them.
    io::RunConfig reloaded;
    io::ApplyConfigYaml(dump, "dump", reloaded);
    EXPECT_EQ(reloaded.descriptor, io::RunConfig{}.descriptor);
    EXPECT_NE(io::DumpParametersMarkdown({}).find(
                  "| `rings.ring_width_m` | 5 | width of a ring (m, 0.1 to 100) |"),
              std::string::npos)
        << io::DumpParametersMarkdown({});
}

}  // namespace
}  // namespace lidarloop
