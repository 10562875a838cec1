#include <string>

#include <gtest/gtest.h>

#include "lidarloop/core/scancontext/scancontext_config.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/read_error.hpp"
#include "test_utils.hpp"

namespace lidarloop::io {
namespace {

std::string ErrorOf(const std::string& yaml) {
    RunConfig config;
    try {
        ApplyConfigYaml(yaml, "my.yaml", config);
    } catch (const ReadError& e) {
        return e.what();
    }
    return "no error";
}

TEST(ConfigYaml, DumpThenLoadGivesTheSameConfig) {
    RunConfig changed;
    changed.descriptor.method = core::Method::kRange;
    changed.descriptor.histogram.bins = 250;
    changed.descriptor.histogram.up_vector = core::UpVectorMode::kPca;
    changed.descriptor.histogram.sensor_height_m = 1.73;
    changed.descriptor.histogram.range_max_m = 120.5;
    changed.descriptor.histogram.out_of_range = core::OutOfRangePolicy::kDrop;
    changed.detection.threshold = 0.0033;
    RunConfig loaded;
    ApplyConfigYaml(DumpConfigYaml(changed), "dump", loaded);
    EXPECT_EQ(DumpConfigYaml(loaded), DumpConfigYaml(changed));
    EXPECT_EQ(loaded.descriptor.method, core::Method::kRange);
    EXPECT_EQ(loaded.descriptor.histogram.bins, 250);
    EXPECT_EQ(loaded.descriptor.histogram.sensor_height_m, 1.73);
    EXPECT_EQ(loaded.detection.threshold, 0.0033);
    EXPECT_EQ(loaded.descriptor.histogram.out_of_range, core::OutOfRangePolicy::kDrop);
}

TEST(ConfigYaml, DumpNamesEveryKeyWithItsDefault) {
    const std::string dump = DumpConfigYaml({});
    for (const char* key :
         {"method: range", "bins: 100", "up_vector: fixed", "sensor_height_m: 0",
          "height_min_m: -3", "height_max_m: 7", "range_min_m: 0", "range_max_m: 80",
          "out_of_range: clamp", "cell_size_m: 0.5", "planar_classes: 9",
          "eigen_ratio_threshold: 0.1", "ambiguity_ratio: 0.6", "range_limits_m: [3, 6, 9, 15]",
          "normalise_rotation: true", "min_gap: 30", "min_gap_unit: scans", "top_k: 10",
          "threshold: default"}) {
        EXPECT_NE(dump.find(key), std::string::npos) << key << " missing in\n" << dump;
    }
}

TEST(ConfigYaml, OverridesOnlyTheNamedKeys) {
    RunConfig config;
    config.descriptor.histogram.range_max_m = 42.0;  // as if set by an earlier file
    ApplyConfigYaml("histogram:\n  bins: 64\n", "x.yaml", config);
    EXPECT_EQ(config.descriptor.histogram.bins, 64);
    EXPECT_EQ(config.descriptor.histogram.range_max_m, 42.0);
    EXPECT_EQ(config.descriptor.method, core::Method::kRange);
}

TEST(ConfigYaml, EmptyDocumentChangesNothing) {
    RunConfig config;
    ApplyConfigYaml("", "empty.yaml", config);
    EXPECT_EQ(DumpConfigYaml(config), DumpConfigYaml({}));
}

// A short section lists its keys; the acceptance rule's has too many to list in a short message
// (a fuzzer's read of a database.scans grew past 600 characters): the nearest key is named.
TEST(ConfigYaml, AnUnknownKeyOfALongSectionNamesTheNearestKey) {
    const std::string typo =
        ErrorOf("verification:\n  acceptance:\n    min_constraining_points_with_motoin: 3\n");
    EXPECT_NE(typo.find("did you mean 'min_constraining_points_with_motion'?"), std::string::npos)
        << typo;
    EXPECT_NE(typo.find("`lidarloop dump-config` lists the"), std::string::npos) << typo;
    EXPECT_LT(typo.size(), 300U) << typo;
    const std::string unlike = ErrorOf("verification:\n  acceptance:\n    colour: red\n");
    EXPECT_EQ(unlike.find("did you mean"), std::string::npos) << unlike;
    EXPECT_NE(unlike.find("unknown key (`lidarloop dump-config`"), std::string::npos) << unlike;
    EXPECT_NE(ErrorOf("histogram:\n  binz: 3\n").find("(valid here: bins, "), std::string::npos);
}

TEST(ConfigYaml, BadInputNamesFileKeyAndProblem) {
    const auto expect_error = [](const std::string& yaml, const std::string& phrase) {
        const std::string message = ErrorOf(yaml);
        EXPECT_NE(message.find("my.yaml"), std::string::npos) << message;
        EXPECT_NE(message.find(phrase), std::string::npos) << message;
    };
    expect_error("histogram:\n  binz: 3\n", "key 'histogram.binz': unknown key");
    expect_error("colour: red\n", "key 'colour': unknown key");
    expect_error("histogram:\n  bins: many\n",
                 "expected an integer in [-2147483648, 2147483647], got 'many'");
    // A count out of its type's range says the range, not only "not an integer".
    expect_error("output:\n  similarity_matrix_mib: -1\n",
                 "expected an integer in [0, 18446744073709551615], got '-1'");
    expect_error("histogram:\n  bins: 2.5\n", "expected an integer");
    expect_error("detection:\n  threshold: [1, 2]\n", "expected a single value");
    expect_error("detection:\n  threshold: many\n", "expected a number or 'default', got 'many'");
    expect_error("detection:\n  threshold: -0.1\n", "detection.threshold must be a finite");
    expect_error("histogram: 5\n", "expected a section");
    expect_error("method: sift\n", "unknown method 'sift'");
    expect_error("histogram:\n  bins: 0\n", "histogram.bins must be in [1, 1000000], got 0");
    expect_error("ndt:\n  eigen_ratio_threshold: 1\n",
                 "ndt.eigen_ratio_threshold must be in (0, 1), got 1");
    expect_error("histogram:\n  up_vector: up\n", "key 'histogram.up_vector': unknown up vector");
    expect_error("histogram:\n  height_min_m: 10\n", "must be smaller than");
    expect_error("histogram: {bins: 3\n", "line");
    expect_error("- a\n- b\n", "expected a map");
    expect_error("detection:\n  min_gap_unit: hours\n", "unknown gap unit 'hours'");
    expect_error("detection:\n  top_k: 0\n", "detection.top_k must be in [1, 1000]");
    expect_error("detection:\n  odometry_shortlist: 0\n",
                 "detection.odometry_shortlist must be in [1, 1000], got 0");
    expect_error("detection:\n  odometry_shortlist: 1001\n",
                 "detection.odometry_shortlist must be in [1, 1000], got 1001");
    expect_error("detection:\n  odometry_shortlist: many\n", "odometry_shortlist");
    expect_error("detection:\n  layout_shortlist: -1\n",
                 "detection.layout_shortlist must be in [0, 1000], got -1");
    expect_error("detection:\n  layout_shortlist: 1001\n",
                 "detection.layout_shortlist must be in [0, 1000], got 1001");
    expect_error("detection:\n  layout_shortlist: many\n", "layout_shortlist");
    expect_error("detection:\n  min_gap: -3\n", "detection.min_gap must be");
}

// Keys that are no plain name were found by fuzzing: yaml-cpp's conversion of such a key to a
// string threw its own exception, which escaped as an internal error.
TEST(ConfigYaml, AKeyThatIsNoNameIsAReadError) {
    const auto expect_error = [](const std::string& yaml, const std::string& phrase) {
        const std::string message = ErrorOf(yaml);
        EXPECT_NE(message.find("my.yaml"), std::string::npos) << yaml << ": " << message;
        EXPECT_NE(message.find(phrase), std::string::npos) << yaml << ": " << message;
    };
    expect_error("? :\n", "line 1: a key at the top level is");
    expect_error("~: 1\n", "line 1: a key at the top level is empty, not a name");
    expect_error("[a]: 1\n", "line 1: a key at the top level is a list, not a name");
    expect_error("histogram:\n  {x: 1}: 2\n",
                 "line 2: a key in section 'histogram' is a map, not a name");
    expect_error("verification:\n  icp:\n    [1, 2]: 3\n", "in section 'verification.icp'");
}

// yaml-cpp 0.7 keeps a repeated key and finds its first value, so the second was ignored silently.
TEST(ConfigYaml, ARepeatedKeyIsAReadErrorNamingKeyAndLines) {
    const auto expect_error = [](const std::string& yaml, const std::string& phrase) {
        const std::string message = ErrorOf(yaml);
        EXPECT_NE(message.find("my.yaml"), std::string::npos) << yaml << ": " << message;
        EXPECT_NE(message.find(phrase), std::string::npos) << yaml << ": " << message;
    };
    expect_error("method: ndt\nmethod: height\n",
                 "line 2: key 'method' appears twice (first on line 1)");
    expect_error("histogram:\n  bins: 12\n  range_max_m: 50\n  bins: 40\n",
                 "line 4: key 'histogram.bins' appears twice (first on line 2)");
    expect_error("histogram:\n  bins: 12\nndt:\n  cell_size_m: 1\nhistogram:\n  bins: 40\n",
                 "line 5: key 'histogram' appears twice (first on line 1)");
    expect_error("posegraph:\n  robust:\n    gate_sigmas: 3\n    gate_sigmas: 4\n",
                 "key 'posegraph.robust.gate_sigmas' appears twice");
    expect_error("histogram: {bins: 3, bins: 4}\n", "key 'histogram.bins' appears twice");
    // The repeat is named even when the first value is bad.
    expect_error("histogram:\n  bins: many\n  bins: 4\n", "appears twice");
}

TEST(ConfigYaml, NdtSectionWithListsAndBooleans) {
    RunConfig config;
    ApplyConfigYaml("method: ndt\nndt:\n  range_limits_m: [2, 4.5]\n  regrid_rotations: true\n",
                    "ndt.yaml", config);
    EXPECT_EQ(config.descriptor.method, core::Method::kNdt);
    EXPECT_EQ(config.descriptor.ndt.range_limits_m, (std::vector<double>{2.0, 4.5}));
    EXPECT_TRUE(config.descriptor.ndt.regrid_rotations);
    const std::string dump = DumpConfigYaml(config);
    EXPECT_NE(dump.find("range_limits_m: [2, 4.5]"), std::string::npos) << dump;
    EXPECT_NE(dump.find("regrid_rotations: true"), std::string::npos) << dump;
    RunConfig reloaded;
    ApplyConfigYaml(dump, "dump", reloaded);
    EXPECT_EQ(DumpConfigYaml(reloaded), dump);
    EXPECT_NE(ErrorOf("ndt:\n  range_limits_m: 3\n").find("expected a list of numbers"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ndt:\n  range_limits_m: [3, x]\n").find("expected a list of numbers"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ndt:\n  regrid_rotations: maybe\n").find("expected true or false"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ndt:\n  range_limits_m: [6, 3]\n").find("strictly increasing"),
              std::string::npos);
}

// A bad value names its key whole, however long; an unknown key of the user's is quoted safely
// (cut at 40 characters).
TEST(ConfigYaml, ABadValueNamesItsKnownKeyWhole) {
    const std::string bad_value =
        ErrorOf("verification:\n  coarse:\n    better_half_turn_only: maybe\n");
    EXPECT_NE(bad_value.find("key 'verification.coarse.better_half_turn_only': expected true or "
                             "false"),
              std::string::npos)
        << bad_value;
    const std::string unknown =
        ErrorOf("verification:\n  coarse:\n    " + std::string(60, 'z') + ": 1\n");
    EXPECT_NE(unknown.find("...' (80 characters)"), std::string::npos) << unknown;
}

TEST(ConfigYaml, ScanContextSectionRoundTripsAndRejectsUnknownKeys) {
    RunConfig config;
    ApplyConfigYaml(
        "method: scancontext\nscancontext:\n  rings: 10\n  sectors: 90\n  max_range_m: 40\n"
        "  sensor_height_m: 1.5\n  ring_key_candidates: 25\n",
        "sc.yaml", config);
    EXPECT_EQ(core::ToString(config.descriptor.method), "scancontext");
    const core::ScanContextConfig& sc =
        config.descriptor.methods.Get<core::ScanContextConfig>("scancontext");
    EXPECT_EQ(sc.rings, 10);
    EXPECT_EQ(sc.sectors, 90);
    EXPECT_EQ(sc.max_range_m, 40.0);
    EXPECT_EQ(sc.sensor_height_m, 1.5);
    EXPECT_EQ(sc.ring_key_candidates, 25);
    const std::string dump = DumpConfigYaml(config);
    EXPECT_NE(dump.find("scancontext:\n  rings: 10"), std::string::npos) << dump;
    RunConfig reloaded;
    ApplyConfigYaml(dump, "dump", reloaded);
    EXPECT_EQ(reloaded.descriptor, config.descriptor);
    // The defaults are shown by dump-config.
    EXPECT_NE(DumpConfigYaml({}).find("scancontext:\n  rings: 20"), std::string::npos);
    EXPECT_NE(ErrorOf("scancontext:\n  ringz: 3\n").find("key 'scancontext.ringz': unknown key"),
              std::string::npos)
        << ErrorOf("scancontext:\n  ringz: 3\n");
    EXPECT_NE(ErrorOf("scancontext:\n  rings: 0\n").find("scancontext.rings must be in [1, 200]"),
              std::string::npos)
        << ErrorOf("scancontext:\n  rings: 0\n");
}

// docs/cli.md's table of descriptor parameters: each row from a declaration, with its default,
// unit and range; names (enums) in code like strings.
TEST(ConfigYaml, ParametersMarkdownHasTheHistogramAndNdtDeclarations) {
    const std::string table = DumpParametersMarkdown({});
    for (const char* row :
         {"| `histogram.bins` | 100 | b, number of buckets (1 to 1000000) |\n",
          "| `histogram.up_vector` | `fixed` | height projection up vector: fixed (0,0,1) \\| pca "
          "|\n",
          "| `histogram.range_min_m` | 0 | v_min of the range histogram (m, >= 0) |\n",
          "| `ndt.cell_size_m` | 0.5 | q, side of an NDT cell; cells overlap by q/2 (m, 0.01 to "
          "100) "
          "|\n",
          "| `ndt.eigen_ratio_threshold` | 0.1 | t_e of the shape classes (0 to 1, exclusive) |\n",
          "| `ndt.range_limits_m` | [3, 6, 9, 15] | borders of the range intervals (m) |\n",
          "| `scancontext.rings` | 20 |"}) {
        EXPECT_NE(table.find(row), std::string::npos) << row << " missing in\n" << table;
    }
    EXPECT_LT(table.find("histogram.out_of_range"), table.find("ndt.cell_size_m"));
    EXPECT_LT(table.find("ndt.regrid_rotations"), table.find("scancontext.rings"));
}

TEST(ConfigYaml, FailedApplyLeavesConfigUnchanged) {
    RunConfig config;
    EXPECT_THROW(ApplyConfigYaml("histogram:\n  bins: 7\n  oops: 1\n", "f", config), ReadError);
    EXPECT_EQ(config.descriptor.histogram.bins, 100);
}

TEST(ConfigYaml, TheThresholdIsUnsetByDefaultOrNull) {
    RunConfig config;
    config.detection.threshold = 0.2;
    ApplyConfigYaml("detection:\n  threshold: default\n", "a", config);
    EXPECT_FALSE(config.detection.threshold.has_value());
    config.detection.threshold = 0.2;
    ApplyConfigYaml("detection:\n  threshold: ~\n", "b", config);
    EXPECT_FALSE(config.detection.threshold.has_value());
    ApplyConfigYaml("detection:\n  threshold: 0.01\n", "c", config);
    EXPECT_EQ(config.detection.threshold, 0.01);
}

// lidarloop 0.1 kept tau and t_d in the descriptor sections; its files still load, or say where
// the key went.
TEST(ConfigYaml, AConfigOfVersion01LoadsWithItsDefaultThresholds) {
    const std::filesystem::path legacy = std::filesystem::path(LIDARLOOP_TEST_DATA_DIR) / "legacy";
    // 0.1 dumped every key; its method (height) and top_k of 5 are the file's own values now
    // that the defaults are range and 10.
    RunConfig expected;
    expected.descriptor.method = core::Method::kHeight;
    expected.detection.top_k = 5;
    EXPECT_EQ(DumpConfigYaml(LoadConfigYaml(legacy / "config_v0.1.yaml")),
              DumpConfigYaml(expected));
    try {
        LoadConfigYaml(legacy / "config_v0.1_threshold.yaml");
        FAIL() << "a threshold of 0.004 under histogram was accepted";
    } catch (const ReadError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("key 'histogram.threshold': moved to 'detection.threshold'"),
                  std::string::npos)
            << message;
        EXPECT_NE(message.find("detection.threshold: 0.004"), std::string::npos) << message;
    }
    EXPECT_NE(ErrorOf("ndt:\n  threshold: 0.05\n").find("key 'ndt.threshold': moved"),
              std::string::npos);
    // A file for ndt with a histogram threshold: the message says whose threshold it was.
    EXPECT_NE(ErrorOf("method: ndt\nhistogram:\n  threshold: 0.004\n").find("for height and range"),
              std::string::npos);
    // A saved database's threshold is that of its method; the other section's is not.
    RunConfig migrated;
    ApplyConfigYaml("method: ndt\nhistogram:\n  threshold: 0.004\nndt:\n  threshold: 0.05\n", "db",
                    migrated, LegacyKeys::kMigrate);
    EXPECT_EQ(migrated.detection.threshold, 0.05);
    RunConfig height;
    ApplyConfigYaml("histogram:\n  threshold: 0.004\nndt:\n  threshold: 0.05\n", "db", height,
                    LegacyKeys::kMigrate);
    EXPECT_EQ(height.detection.threshold, 0.004);
}

TEST(ConfigYaml, FileRoundTripAndMissingFile) {
    test::TempDir dir;
    RunConfig config;
    config.descriptor.histogram.bins = 33;
    WriteConfigYaml(dir / "config.yaml", config);
    EXPECT_EQ(LoadConfigYaml(dir / "config.yaml").descriptor.histogram.bins, 33);
    EXPECT_THROW(LoadConfigYaml(dir / "missing.yaml"), ReadError);
}

}  // namespace
}  // namespace lidarloop::io
