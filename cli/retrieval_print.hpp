#pragma once

#include "lidarloop/app/retrieval_evaluation.hpp"

namespace lidarloop::cli {

/// Prints the online detector's figures of one method: the candidates' ceiling (recall@1,
/// recall@k), then the loops the descriptor threshold and verification accept.
void PrintRetrieval(const app::RetrievalComparison& r);

}  // namespace lidarloop::cli
