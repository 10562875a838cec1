#include "retrieval_print.hpp"

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

namespace lidarloop::cli {
namespace {

// A share of no revisiting scan (or no loop) is undefined, not 0 %: "–", as report.md writes it.
std::string Percent(double rate) {
    if (std::isnan(rate)) return "–";
    std::ostringstream text;
    text << 100.0 * rate << " %";
    return text.str();
}

void PrintLoops(const std::string& label, const eval::LoopRetrievalEvaluation& r) {
    std::cout << "      " << label << ": " << r.true_loops << " true and " << r.false_loops
              << " false loops";
    if (r.loops_with_pose > 0) std::cout << " (" << r.wrong_pose_loops << " at a wrong pose)";
    std::cout << ", recall at 100 % precision " << Percent(r.full_precision.recall);
    if (r.pose_error.translation_m) {
        std::cout << ", pose error median " << r.pose_error.translation_m->median << " m / "
                  << r.pose_error.yaw_deg->median << " deg yaw";
    }
    std::cout << "\n";
}

}  // namespace

void PrintRetrieval(const app::RetrievalComparison& r) {
    std::cout << "    top-" << r.top_k << " candidates of " << r.descriptor.revisiting
              << " revisiting scans: recall@1 " << Percent(r.descriptor.recall_at_1) << ", recall@"
              << r.top_k << " " << Percent(r.descriptor.recall_at_k) << "\n";
    PrintLoops("descriptor threshold", r.descriptor);
    if (r.verified) PrintLoops("verified", *r.verified);
}

}  // namespace lidarloop::cli
