// Evaluates every method on a sequence with ground-truth poses, as `lidarloop evaluate` does,
// through the run layer: same-place pairs within 10 m, both papers' protocols, a results folder.
// Usage: evaluate_sequence DATASET OUT_FOLDER
#include <cstdio>
#include <exception>

#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace ll = lidarloop;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s DATASET OUT_FOLDER\n", argv[0]);
        return 2;
    }
    try {
        const ll::io::Dataset dataset = ll::io::OpenDataset(argv[1]);  // needs poses
        ll::app::EvaluationRequest request;  // Röhling's rule: same place within 10 m
        for (const std::string& name : ll::pipeline::MethodNames())
            request.methods.push_back(ll::pipeline::ParseMethod(name));
        request.out = argv[2];
        const ll::app::EvaluationOutcome outcome = ll::app::RunEvaluation(dataset, request);
        std::printf("%s\n", outcome.truth.Describe().c_str());
        for (const ll::app::MethodEvaluation& e : outcome.methods) {
            std::printf("%s: best MCC %.3f at %.4g, ROC AUC %.3f, recall at zero errors %.1f %%\n",
                        e.name.c_str(), e.pairwise.best_mcc.score, e.pairwise.best_mcc.threshold,
                        e.pairwise.roc_auc.value_or(0.0), 100.0 * e.per_scan.zero_error.recall);
        }
        std::printf("report: %s/report.md\n", argv[2]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
