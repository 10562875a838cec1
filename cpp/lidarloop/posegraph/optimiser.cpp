
#include "lidarloop/posegraph/optimiser.hpp"
#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/product_manifold.h>
#include <ceres/solver.h>
#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::posegraph {
namespace {

// Relative cost change that ends an intermediate graduated round (Ceres' default: 1e-6).
constexpr double kRoughFunctionTolerance = 1e-3;

// The whitened g2o EDGE_SE3:QUAT error of one edge (EdgeError), for Ceres' automatic
// differentiation. Parameters: the poses of `from` and `to`, each x y z qx qy qz qw.
class RelativePoseCost {
public:
    RelativePoseCost(const core::Transform& T_from_to, const Matrix6d& information)
        : q_to_from_(Eigen::Quaterniond(T_from_to.linear()).normalized().conjugate()),
          t_from_to_(T_from_to.translation()),
          sqrt_information_(information.llt().matrixU()) {}

    template <typename T>
    bool operator()(const T* from, const T* to, T* residual) const {
        using Vector3 = Eigen::Matrix<T, 3, 1>;
        const Eigen::Map<const Vector3> position_from(from);
        const Eigen::Map<const Vector3> position_to(to);
        const Eigen::Map<const Eigen::Quaternion<T>> rotation_from(from + 3);
        const Eigen::Map<const Eigen::Quaternion<T>> rotation_to(to + 3);
        // The estimate of T_from_to, then delta = measured^-1 * estimate.
        const Eigen::Quaternion<T> q_from_inverse = rotation_from.conjugate();
        const Vector3 t_estimate = q_from_inverse * (position_to - position_from);
        const Eigen::Quaternion<T> q_estimate = q_from_inverse * rotation_to;
        const Eigen::Quaternion<T> q_measured_inverse = q_to_from_.cast<T>();
        const Eigen::Quaternion<T> q_delta = q_measured_inverse * q_estimate;
        Eigen::Matrix<T, 6, 1> error;
        error.template head<3>() = q_measured_inverse * (t_estimate - t_from_to_.cast<T>());
        // The quaternion with w >= 0, as g2o's toCompactQuaternion.
        const T sign = q_delta.w() < T(0) ? T(-1) : T(1);
        error.template tail<3>() = sign * q_delta.vec();
        Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
        whitened = sqrt_information_.cast<T>() * error;
        return true;
    }

private:
    Eigen::Quaterniond q_to_from_;
    Eigen::Vector3d t_from_to_;
    Matrix6d sqrt_information_;  // upper triangular U, U^T U = information
};

// Poses as Ceres parameter blocks of 7: position x y z, then the unit quaternion x y z w (one
// block per pose keeps the sparse normal equations in 6x6 blocks: twice as fast to factor as
// separate position and rotation blocks on a 5,000-pose graph).
using PoseManifold =
    ceres::ProductManifold<ceres::EuclideanManifold<3>, ceres::EigenQuaternionManifold>;

struct State {
    std::vector<std::array<double, 7>> poses;

    explicit State(const std::vector<core::Transform>& transforms) : poses(transforms.size()) {
        for (std::size_t i = 0; i < transforms.size(); ++i) {
            Eigen::Map<Eigen::Vector3d>(poses[i].data()) = transforms[i].translation();
            Eigen::Map<Eigen::Quaterniond>(poses[i].data() + 3) =
                Eigen::Quaterniond(transforms[i].linear()).normalized();
        }
    }

    core::Transform Pose(std::size_t i) const {
        core::Transform T = core::Transform::Identity();
        T.linear() = Eigen::Map<const Eigen::Quaterniond>(poses[i].data() + 3)
                         .normalized()
                         .toRotationMatrix();
        T.translation() = Eigen::Map<const Eigen::Vector3d>(poses[i].data());
        return T;
    }
};

double WhitenedResidual(const Edge& edge, const State& state) {
    const Vector6d e = EdgeError(edge.T_from_to, state.Pose(edge.from), state.Pose(edge.to));
    return std::sqrt(std::max(0.0, e.dot(edge.information * e)));
}

// Farther than any Earth-fixed frame reaches, as the pose readers hold (io::ReadPoses): the
// solver on coordinates of 1e200 m does not come back.
constexpr double kMaxCoordinateM = 1e8;

bool Reasonable(const core::Transform& T) {
    return T.matrix().allFinite() && T.translation().norm() <= kMaxCoordinateM;
}

void CheckGraph(const PoseGraph& graph) {
    if (graph.poses.empty()) throw core::ConfigError("the pose graph has no pose");
    if (!graph.path_m.empty() && graph.path_m.size() != graph.poses.size())
        throw core::ConfigError("the pose graph's path has not one length per pose");
    for (std::size_t i = 0; i < graph.poses.size(); ++i) {
        if (!Reasonable(graph.poses[i])) {
            throw core::ConfigError("pose " + std::to_string(i) +
                                    " of the pose graph is not finite or lies more than 1e8 m "
                                    "from the origin");
        }
    }
    RequireEdgesWithin(graph.edges, graph.poses.size());
    for (const Edge& edge : graph.edges) {
        if (!Reasonable(edge.T_from_to) || !edge.information.allFinite()) {
            throw core::ConfigError("the edge from pose " + std::to_string(edge.from) + " to " +
                                    std::to_string(edge.to) +
                                    " is not finite or spans more than 1e8 m");
        }
    }
}

// Distance travelled from pose 0 to each pose: the graph's path, else along the initial estimate
// (the odometry).
std::vector<double> PathLengths(const PoseGraph& graph) {
    if (!graph.path_m.empty()) return graph.path_m;
    const std::vector<core::Transform>& poses = graph.poses;
    std::vector<double> path(poses.size(), 0.0);
    for (std::size_t i = 1; i < poses.size(); ++i) {
        path[i] = path[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
    }
    return path;
}

// The odometry gate of one edge (GateAgainstOdometry).
LoopResult GateLoop(const Edge& edge, const PoseGraph& graph, const std::vector<double>& path,
                    const PoseGraphConfig& config) {
    const core::Transform T_odometry = graph.poses[edge.from].inverse() * graph.poses[edge.to];
    LoopResult result = GateAgainstOdometry(edge.T_from_to, T_odometry,
                                            std::abs(path[edge.to] - path[edge.from]), config);
    result.loop = edge.loop;
    return result;
}

struct SolveStats {
    int iterations = 0;
    bool converged = true;
};

// One Ceres solve of the odometry edges and the loops still used, a Cauchy loss of scale
// `cauchy_scale` (whitened units) on the loops; pose 0 fixed.
SolveStats Solve(const PoseGraph& graph, const std::vector<const Edge*>& loops, double cauchy_scale,
                 const PoseGraphConfig& config, State& state, bool rough = false) {
    PoseManifold pose_manifold;
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    const auto add = [&](const Edge& edge, ceres::LossFunction* loss) {
        auto* cost = new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 7, 7>(
            new RelativePoseCost(edge.T_from_to, edge.information));
        problem.AddResidualBlock(cost, loss, state.poses[edge.from].data(),
                                 state.poses[edge.to].data());
    };
    for (const Edge& edge : graph.edges) {
        if (edge.kind == Edge::Kind::kOdometry) add(edge, nullptr);
    }
    for (const Edge* edge : loops) add(*edge, new ceres::CauchyLoss(cauchy_scale));
    for (auto& pose : state.poses) {
        if (problem.HasParameterBlock(pose.data()))
            problem.SetManifold(pose.data(), &pose_manifold);
    }
    if (!problem.HasParameterBlock(state.poses[0].data())) return {};
    problem.SetParameterBlockConstant(state.poses[0].data());

    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.max_num_iterations = config.max_iterations;
    options.num_threads = config.threads;
    options.logging_type = ceres::SILENT;
    options.minimizer_progress_to_stdout = false;
    // Powell's dogleg: fewer iterations than Levenberg-Marquardt on these graphs (15 against
    // 23 on the 5,000-pose benchmark), each a sparse Cholesky of the same normal equations.
    options.trust_region_strategy_type = ceres::DOGLEG;
    if (rough) options.function_tolerance = kRoughFunctionTolerance;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    return {static_cast<int>(summary.iterations.size()),
            summary.termination_type == ceres::CONVERGENCE};
}

double Cost(const PoseGraph& graph, const std::vector<const Edge*>& loops, const State& state) {
    double cost = 0.0;
    const auto add = [&](const Edge& edge) {
        const double r = WhitenedResidual(edge, state);
        cost += 0.5 * r * r;
    };
    for (const Edge& edge : graph.edges) {
        if (edge.kind == Edge::Kind::kOdometry) add(edge);
    }
    for (const Edge* edge : loops) add(*edge);
    return cost;
}

double Median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

}  // namespace

std::string ToString(LoopVerdict verdict) {
    switch (verdict) {
        case LoopVerdict::kUsed:
            return "used";
        case LoopVerdict::kRejectedByOdometry:
            return "rejected_by_odometry";
        case LoopVerdict::kRejectedByResidual:
            return "rejected_by_residual";
        case LoopVerdict::kRejectedByConsistency:
            return "rejected_by_consistency";
    }
    return "unknown";
}

namespace {

// The loops still used, with their results; `results` and `used` index the graph's loop edges.
struct LoopSet {
    std::vector<const Edge*> edges;
    std::vector<LoopResult> results;

    std::vector<const Edge*> Used() const {
        std::vector<const Edge*> used;
        for (std::size_t k = 0; k < edges.size(); ++k) {
            if (results[k].verdict == LoopVerdict::kUsed) used.push_back(edges[k]);
        }
        return used;
    }
};

void Accumulate(const SolveStats& stats, OptimisationResult& result) {
    ++result.solves;
    result.iterations += stats.iterations;
    result.converged = result.converged && stats.converged;
}

// Sigmas (translation m, rotation deg) of a loop from its information.
Eigen::Vector2d LoopSigmas(const Edge& edge) {
    return {1.0 / std::sqrt(edge.information(0, 0)),
            2.0 / std::sqrt(edge.information(3, 3)) / core::kRadiansPerDegree};
}

// Whether loops a and b agree: T_m1_q1 * T_q1_q2 against T_m1_m2 * T_m2_q2, with the odometry
// between their ends (short pieces), within the drift over those pieces and both loops' sigmas.
bool Consistent(const Edge& a, const Edge& b, const PoseGraph& graph,
                const std::vector<double>& path, const PoseGraphConfig& config) {
    const auto& O = graph.poses;
    const core::Transform via_a = a.T_from_to * (O[a.to].inverse() * O[b.to]);
    const core::Transform via_b = (O[a.from].inverse() * O[b.from]) * b.T_from_to;
    const core::Transform error = via_b.inverse() * via_a;
    const double d = std::abs(path[a.from] - path[b.from]) + std::abs(path[a.to] - path[b.to]);
    const InformationConfig& info = config.information;
    const RobustConfig& robust = config.robust;
    const double a_t = info.odometry_translation_sigma_m_per_sqrt_m;
    const double a_r = info.odometry_rotation_sigma_deg_per_sqrt_m * core::kRadiansPerDegree;
    const Eigen::Vector2d loops =
        (LoopSigmas(a).array().square() + LoopSigmas(b).array().square()).sqrt().matrix();
    const double sigma_t =
        std::sqrt(a_t * a_t * d + a_r * a_r * d * d * d / 3.0 + loops.x() * loops.x());
    const double sigma_r_deg =
        std::hypot(info.odometry_rotation_sigma_deg_per_sqrt_m * std::sqrt(d), loops.y());
    const double tolerance_t =
        robust.gate_sigmas * sigma_t + robust.gate_translation_percent / 100.0 * d;
    const double tolerance_r =
        robust.gate_sigmas * sigma_r_deg + robust.gate_rotation_deg_per_100m / 100.0 * d;
    return error.translation().norm() <= tolerance_t &&
           Eigen::AngleAxisd(error.linear()).angle() / core::kRadiansPerDegree <= tolerance_r;
}

// Counts each gated loop's consistent neighbours (loops whose ends both lie within
// support_window_m of its own along the path) and holds out those with too few; when none has
// enough, every gated loop stays in.
void SupportTest(const PoseGraph& graph, const std::vector<double>& path,
                 const PoseGraphConfig& config, LoopSet& loops) {
    const RobustConfig& robust = config.robust;
    if (robust.min_support == 0) return;
    std::vector<std::size_t> order;  // gated loops by the path position of their query
    for (std::size_t k = 0; k < loops.edges.size(); ++k) {
        if (loops.results[k].verdict == LoopVerdict::kUsed) order.push_back(k);
    }
    std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
        return path[loops.edges[x]->to] < path[loops.edges[y]->to];
    });
    std::size_t begin = 0;
    bool any_supported = false;
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Edge& a = *loops.edges[order[i]];
        while (path[loops.edges[order[begin]]->to] < path[a.to] - robust.support_window_m) ++begin;
        std::size_t& support = loops.results[order[i]].support;
        for (std::size_t j = begin; j < order.size(); ++j) {
            const Edge& b = *loops.edges[order[j]];
            if (path[b.to] > path[a.to] + robust.support_window_m) break;
            if (j == i || std::abs(path[b.from] - path[a.from]) > robust.support_window_m) continue;
            if (Consistent(a, b, graph, path, config)) ++support;
        }
        any_supported = any_supported || support >= static_cast<std::size_t>(robust.min_support);
    }
    if (!any_supported) return;
    for (const std::size_t k : order) {
        if (loops.results[k].support < static_cast<std::size_t>(robust.min_support)) {
            loops.results[k].verdict = LoopVerdict::kRejectedByConsistency;
        }
    }
}

// Graduated rounds: from the median whitened residual of the loops at the odometry down to the
// final Cauchy scale, each round starting where the last ended.
void GraduatedSolve(const PoseGraph& graph, LoopSet& loops, const PoseGraphConfig& config,
                    State& state, OptimisationResult& result) {
    std::vector<double> initial;
    for (std::size_t k = 0; k < loops.edges.size(); ++k) {
        if (loops.results[k].verdict == LoopVerdict::kUsed)
            initial.push_back(loops.results[k].initial_whitened_residual);
    }
    const double final_scale = config.robust.cauchy_scale;
    double scale = std::max(Median(initial), final_scale);
    const std::vector<const Edge*> used = loops.Used();
    while (true) {
        // The intermediate rounds only steer the final one: a looser stop suffices.
        Accumulate(Solve(graph, used, scale, config, state, scale > final_scale), result);
        if (scale <= final_scale) break;
        scale = std::max(scale / config.robust.scale_step, final_scale);
    }
}

// Tests every loop against the optimised graph: a used loop whose whitened residual exceeds
// reject_sigmas is dropped, and a rejected one (by the gate, whose tolerance is loose or tight
// only as the drift model is right, or by an earlier round) within it is taken back; then the
// graph is solved again, until the set of used loops stays or the rounds are used up.
void RejectAndResolve(const PoseGraph& graph, LoopSet& loops, const PoseGraphConfig& config,
                      State& state, OptimisationResult& result) {
    for (int round = 0; round <= config.robust.max_reject_rounds; ++round) {
        const bool last = round == config.robust.max_reject_rounds;
        bool changed = false;
        for (std::size_t k = 0; k < loops.edges.size(); ++k) {
            LoopResult& loop = loops.results[k];
            const double residual = WhitenedResidual(*loops.edges[k], state);
            const bool used = loop.verdict == LoopVerdict::kUsed;
            if (used) loop.whitened_residual = residual;
            if (last) continue;
            const bool consistent = residual <= config.robust.reject_sigmas;
            if (used && !consistent) {
                loop.verdict = LoopVerdict::kRejectedByResidual;
                changed = true;
            } else if (!used && consistent) {
                loop.verdict = LoopVerdict::kUsed;
                loop.whitened_residual = residual;
                changed = true;
            }
        }
        if (!changed) return;
        Accumulate(Solve(graph, loops.Used(), config.robust.cauchy_scale, config, state), result);
    }
}

// The drift in position the information model allows over `d` metres of path: a random walk in
// position and heading (the heading's walk moves the position by about a_r * sqrt(d^3 / 3)).
double TranslationSigmaM(double d, const InformationConfig& info) {
    const double a_t = info.odometry_translation_sigma_m_per_sqrt_m;
    const double a_r = info.odometry_rotation_sigma_deg_per_sqrt_m * core::kRadiansPerDegree;
    return std::sqrt(a_t * a_t * d + a_r * a_r * d * d * d / 3.0);
}

}  // namespace

double GateTranslationM(double path_m, const PoseGraphConfig& config) {
    const RobustConfig& robust = config.robust;
    return robust.gate_sigmas * TranslationSigmaM(path_m, config.information) +
           robust.gate_min_translation_m + robust.gate_translation_percent / 100.0 * path_m;
}

// The heading's random walk alone.
double GateRotationDeg(double path_m, const PoseGraphConfig& config) {
    const RobustConfig& robust = config.robust;
    const double sigma_r_deg =
        config.information.odometry_rotation_sigma_deg_per_sqrt_m * std::sqrt(path_m);
    return robust.gate_sigmas * sigma_r_deg + robust.gate_min_rotation_deg +
           robust.gate_rotation_deg_per_100m / 100.0 * path_m;
}

LoopResult GateAgainstOdometry(const core::Transform& T_from_to_loop,
                               const core::Transform& T_from_to_odometry, double path_m,
                               const PoseGraphConfig& config) {
    LoopResult result;
    result.path_m = path_m;
    const core::Transform discrepancy = T_from_to_loop.inverse() * T_from_to_odometry;
    result.odometry_translation_error_m = discrepancy.translation().norm();
    result.odometry_rotation_error_deg =
        Eigen::AngleAxisd(discrepancy.linear()).angle() / core::kRadiansPerDegree;
    result.gate_translation_m = GateTranslationM(path_m, config);
    result.gate_rotation_deg = GateRotationDeg(path_m, config);
    const bool passes = result.odometry_translation_error_m <= result.gate_translation_m &&
                        result.odometry_rotation_error_deg <= result.gate_rotation_deg;
    if (!passes) result.verdict = LoopVerdict::kRejectedByOdometry;
    return result;
}

OptimisationResult Optimise(const PoseGraph& graph, const PoseGraphConfig& config) {
    const auto start = std::chrono::steady_clock::now();
    config.Validate();
    CheckGraph(graph);
    OptimisationResult result;
    result.poses = graph.poses;
    const std::vector<double> path = PathLengths(graph);
    const State initial(graph.poses);
    LoopSet loops;
    for (const Edge& edge : graph.edges) {
        if (edge.kind != Edge::Kind::kLoop) continue;
        loops.edges.push_back(&edge);
        LoopResult loop = GateLoop(edge, graph, path, config);
        loop.initial_whitened_residual = WhitenedResidual(edge, initial);
        loop.whitened_residual = loop.verdict == LoopVerdict::kUsed
                                     ? loop.initial_whitened_residual
                                     : std::numeric_limits<double>::quiet_NaN();
        loops.results.push_back(loop);
    }
    SupportTest(graph, path, config, loops);
    result.initial_cost = Cost(graph, loops.Used(), initial);
    if (loops.Used().empty()) {
        result.note = loops.edges.empty()
                          ? "no loop: the odometry is returned unchanged"
                          : "every loop was rejected by the odometry gate: the odometry is "
                            "returned unchanged";
        result.final_cost = result.initial_cost;
    } else {
        State state = initial;
        GraduatedSolve(graph, loops, config, state, result);
        RejectAndResolve(graph, loops, config, state, result);
        for (std::size_t i = 0; i < result.poses.size(); ++i) result.poses[i] = state.Pose(i);
        result.final_cost = Cost(graph, loops.Used(), state);
    }
    for (const LoopResult& loop : loops.results) {
        result.loops_used += loop.verdict == LoopVerdict::kUsed ? 1 : 0;
        result.rejected_by_odometry += loop.verdict == LoopVerdict::kRejectedByOdometry ? 1 : 0;
        result.rejected_by_residual += loop.verdict == LoopVerdict::kRejectedByResidual ? 1 : 0;
        result.rejected_by_consistency +=
            loop.verdict == LoopVerdict::kRejectedByConsistency ? 1 : 0;
    }
    result.loops = std::move(loops.results);
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

namespace {

// Steps shorter than this are a standstill (a frozen odometry repeats its pose exactly).
constexpr double kStandstillStepM = 1e-6;

std::string Metres(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), value < 10.0 ? "%.2f m" : "%.1f m", value);
    return text;
}

// What in the odometry may make it disagree with the loops: its largest step (a reset or a
// jump), against the median step, and its longest run of repeated poses (a freeze).
std::string OdometryEvidence(const std::vector<core::Transform>& poses) {
    if (poses.size() < 2) return "";
    std::vector<double> steps;
    std::size_t largest = 0, run_begin = 0, best_begin = 0, best_length = 0;
    for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
        steps.push_back((poses[i + 1].translation() - poses[i].translation()).norm());
        if (steps[i] > steps[largest]) largest = i;
        if (steps[i] >= kStandstillStepM) run_begin = i + 1;
        if (i + 1 - run_begin > best_length) {
            best_begin = run_begin;
            best_length = i + 1 - run_begin;
        }
    }
    const double largest_m = steps[largest];
    std::string text = "largest step " + Metres(largest_m) + ", median " + Metres(Median(steps)) +
                       ", from scan " + std::to_string(largest) + " to " +
                       std::to_string(largest + 1) + "; ";
    if (best_length == 0) return text + "no standstill";
    return text + "longest standstill: scans " + std::to_string(best_begin) + " to " +
           std::to_string(best_begin + best_length);
}

}  // namespace

std::string SummariseRejections(const PoseGraph& graph, const OptimisationResult& result) {
    const std::size_t total = result.loops.size();
    const std::size_t rejected = total - result.loops_used;
    // One or two rejected loops are wrong loops more likely than a broken odometry.
    constexpr std::size_t kEnMasse = 3;
    if (rejected < kEnMasse || 2 * rejected <= total) return "";
    std::string text =
        std::to_string(rejected) + " of " + std::to_string(total) + " loops rejected, ";
    // The gate compares each loop with the odometry alone: when it rejects most, the odometry
    // is the suspect; otherwise the loops disagree with each other or with the optimised graph.
    if (2 * result.rejected_by_odometry >= rejected) {
        text += std::to_string(result.rejected_by_odometry) +
                " of them against the odometry: does the odometry reset or freeze?";
    } else {
        text += std::to_string(result.rejected_by_odometry) + " against the odometry, " +
                std::to_string(result.rejected_by_consistency) + " without support, " +
                std::to_string(result.rejected_by_residual) +
                " by their residual: are the loops of this sequence, and is the odometry right?";
    }
    const std::string evidence = OdometryEvidence(graph.poses);
    return evidence.empty() ? text : text + " (" + evidence + ")";
}

}  // namespace lidarloop::posegraph
