#include "lidarloop/eval/streamed_pairwise.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <new>
#include <string>
#include <unordered_map>
#include <utility>

#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/detail/slot_counts.hpp"
#include "lidarloop/eval/detail/sweep.hpp"

// How the streamed sweep equals the sweep over sorted pairs (docs/evaluation.md):
// - The positives are kept, sorted into their distinct finite distances D_0 < ... < D_{U-1}.
//   Each negative is counted in a slot: below D_k (2k), at D_k (2k + 1), above all (2U). At
//   every D_k the sweep's confusion is then known exactly, and so is the ROC area (only FP grows
//   between two D_k, by the slot's count, at constant TP).
// - Between D_{k-1} and D_k lie the negatives' distinct distances, which the sweep also visits.
//   The thinned curve keeps, of those, the first point in each new FPR + TPR bucket: the point
//   whose cumulative FP first reaches a count known after the first pass, i.e. an order
//   statistic of the negatives. The first pass histograms the negatives by the top 20 bits of
//   an order-preserving key of the float, the second counts each key in the few buckets that
//   hold a wanted rank: its value and its cumulative count are then exact.
// - MCC and F1 at a fixed TP fall as FP grows while they are positive, so their optimum is at a
//   D_k, or (when no score is positive) at the first or the last point, whose distances are the
//   negatives' extremes. StreamedResult::optimum_exact names the one case left open.

namespace lidarloop::eval {
namespace {

constexpr int kFineBits = 12;
constexpr std::size_t kCoarseBuckets = std::size_t{1} << (32 - kFineBits);
constexpr std::size_t kFineKeys = std::size_t{1} << kFineBits;
constexpr std::size_t kBitmapWords = (std::size_t{1} << 32) / 64;
constexpr std::size_t kPending = std::size_t{1} << 18;  // negatives a sink sorts at once

// A key whose unsigned order is the float order (-0 and +0 are one value, as `<` sees them).
std::uint32_t OrderKey(float distance) {
    const auto bits = std::bit_cast<std::uint32_t>(distance == 0.0f ? 0.0f : distance);
    return (bits & 0x80000000u) != 0 ? ~bits : bits | 0x80000000u;
}

float FromKey(std::uint32_t key) {
    const std::uint32_t bits = (key & 0x80000000u) != 0 ? key & 0x7fffffffu : ~key;
    return std::bit_cast<float>(bits);
}

void CheckNotNan(std::size_t i, std::size_t j, float distance) {
    if (std::isnan(distance)) {
        throw core::ConfigError("pair-wise evaluation: distance of pair " + detail::PairName(i, j) +
                                " is NaN");
    }
}

constexpr std::uint32_t kZeroKey = 0x80000000u;  // OrderKey of -0 and +0

using detail::SlotCounts;

// The positives of one population by distinct finite distance, and the slot of a negative.
// 5 bytes a distinct distance: its order key and a count that is almost always small.
struct PositiveLevels {
    std::vector<std::uint32_t> keys;         // OrderKey of each distinct finite distance, ascending
    std::vector<std::uint8_t> small_counts;  // positives at each; kLarge: see large_counts
    std::unordered_map<std::size_t, std::uint64_t> large_counts;
    float zero = 0.0f;        // the distance at kZeroKey: -0 or +0, as it came first
    std::uint64_t total = 0;  // unscored included
    // The first distance whose key's coarse bucket is >= b: a slot is then searched among the
    // few distances of one bucket, not all (a binary search over all cost most of the time).
    std::vector<std::uint32_t> first_in_bucket;
    static constexpr std::uint8_t kLarge = 255;

    std::size_t size() const { return keys.size(); }
    float Distance(std::size_t k) const { return keys[k] == kZeroKey ? zero : FromKey(keys[k]); }
    std::uint64_t Count(std::size_t k) const {
        return small_counts[k] < kLarge ? small_counts[k] : large_counts.at(k);
    }
    void Append(float distance, std::uint64_t count) {
        if (OrderKey(distance) == kZeroKey) zero = distance;
        keys.push_back(OrderKey(distance));
        small_counts.push_back(count < kLarge ? static_cast<std::uint8_t>(count) : kLarge);
        if (count >= kLarge) large_counts[keys.size() - 1] = count;
    }
    void Index() {
        first_in_bucket.assign(kCoarseBuckets + 1, 0);
        std::size_t k = 0;
        for (std::size_t b = 0; b <= kCoarseBuckets; ++b) {
            while (k < keys.size() && (keys[k] >> kFineBits) < b) ++k;
            first_in_bucket[b] = static_cast<std::uint32_t>(k);
        }
    }
    std::size_t SlotCount() const { return 2 * keys.size() + 1; }
    // Positives with a finite distance <= threshold.
    std::uint64_t AtMost(double threshold) const {
        std::uint64_t count = 0;
        for (std::size_t k = 0; k < size() && static_cast<double>(Distance(k)) <= threshold; ++k)
            count += Count(k);
        return count;
    }
};

// Sorts keys ascending: LSD radix sort in three passes of 11 bits, O(n) and cache-friendly.
void RadixSort(std::vector<std::uint32_t>& keys, std::vector<std::uint32_t>& scratch) {
    constexpr std::uint32_t kDigits = 2048;
    scratch.resize(keys.size());
    for (unsigned shift = 0; shift < 32; shift += 11) {
        std::array<std::size_t, kDigits> offsets{};
        for (const std::uint32_t key : keys) ++offsets[(key >> shift) & (kDigits - 1)];
        std::size_t sum = 0;
        for (std::size_t& offset : offsets) sum += std::exchange(offset, sum);
        for (const std::uint32_t key : keys)
            scratch[offsets[(key >> shift) & (kDigits - 1)]++] = key;
        keys.swap(scratch);
    }
}

// The first level whose key is >= key, given that none before `from` is: a binary search among
// the distances of key's coarse bucket, which can hold thousands when the positives are many,
// instead of a walk through them one by one under the counting lock.
std::size_t FirstNotBelow(const PositiveLevels& levels, std::uint32_t key, std::size_t from) {
    const std::size_t bucket = key >> kFineBits;
    const auto first = levels.keys.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(
                                                 from, levels.first_in_bucket[bucket]));
    const auto last =
        levels.keys.begin() + static_cast<std::ptrdiff_t>(levels.first_in_bucket[bucket + 1]);
    return static_cast<std::size_t>(std::lower_bound(first, last, key) - levels.keys.begin());
}

// A located batch entry: (slot or coarse bucket << kCountBits) | count, where a count is at
// most a batch (kPending).
constexpr unsigned kCountBits = 20;
constexpr std::uint64_t kCountMask = (std::uint64_t{1} << kCountBits) - 1;
static_assert(kPending <= kCountMask);

// Locates ascending keys of negatives in the slots between `levels` (below D_k: 2k, at D_k:
// 2k + 1), walking both in order: one located entry per distinct key, also given to `each_key`
// with its count. Reads only what is fixed during the pass, so it runs outside the lock.
template <class EachKey>
void LocateSortedKeys(const std::vector<std::uint32_t>& keys, const PositiveLevels& levels,
                      std::vector<std::uint64_t>& located, EachKey each_key) {
    located.clear();
    std::size_t k = 0;
    for (std::size_t a = 0; a < keys.size();) {
        const std::uint32_t key = keys[a];
        std::size_t b = a + 1;
        while (b < keys.size() && keys[b] == key) ++b;
        k = FirstNotBelow(levels, key, k);
        const std::uint64_t slot =
            2 * k + (k < levels.keys.size() && levels.keys[k] == key ? 1 : 0);
        located.push_back((slot << kCountBits) | (b - a));
        each_key(key, static_cast<std::uint64_t>(b - a));
        a = b;
    }
}

void AddLocated(const std::vector<std::uint64_t>& located, SlotCounts& slots) {
    for (const std::uint64_t entry : located) slots.Add(entry >> kCountBits, entry & kCountMask);
}

// The levels of `distances` (all of one population, unscored included), which it sorts. The
// same sort of the same sequence as before these levels were compact, so that of -0 and +0 the
// same one comes first.
PositiveLevels LevelsOf(std::vector<float>& distances) {
    PositiveLevels levels;
    levels.total = distances.size();
    distances.erase(std::remove_if(distances.begin(), distances.end(),
                                   [](float d) { return !detail::IsScored(d); }),
                    distances.end());
    std::sort(distances.begin(), distances.end());
    // Exactly as many levels as distinct distances: growing by doubling would need twice that.
    std::size_t distinct = 0;
    for (std::size_t a = 0; a < distances.size(); ++a)
        distinct += a == 0 || distances[a] != distances[a - 1] ? 1 : 0;
    levels.keys.reserve(distinct);
    levels.small_counts.reserve(distinct);
    for (std::size_t a = 0; a < distances.size();) {
        std::size_t b = a + 1;
        while (b < distances.size() && distances[b] == distances[a]) ++b;
        levels.Append(distances[a], b - a);
        a = b;
    }
    levels.Index();
    return levels;
}

struct FreeDeleter {
    void operator()(std::uint64_t* p) const { std::free(p); }
};

// One bit per float key. calloc leaves untouched pages unmapped, so only the pages of keys
// that occur become resident.
std::unique_ptr<std::uint64_t, FreeDeleter> NewBitmap() {
    auto* words = static_cast<std::uint64_t*>(std::calloc(kBitmapWords, sizeof(std::uint64_t)));
    if (words == nullptr) throw std::bad_alloc();
    return std::unique_ptr<std::uint64_t, FreeDeleter>(words);
}

// A wanted order statistic of the finite negatives: rank (1-based) and, after the first pass,
// where it lies; after the second, its value and how many negatives are <= it.
struct RankQuery {
    std::uint64_t rank = 0;
    std::uint32_t bucket = 0;
    std::uint64_t rank_in_bucket = 0;
    float value = 0.0f;
    std::uint64_t at_most = 0;
};

Confusion ConfusionOf(std::uint64_t tp, std::uint64_t fp, std::uint64_t positives,
                      std::uint64_t negatives) {
    return {tp, fp, negatives - fp, positives - tp};
}

// The negatives' count, extremes and unscored pairs of one population (all, training, test).
struct NegativeExtremes {
    float min = 0.0f;
    float max = 0.0f;
    std::uint64_t min_count = 0;
    std::uint64_t max_count = 0;
    std::uint64_t unscored = 0;
    std::uint64_t total = 0;

    void Add(float distance) {
        ++total;
        if (!detail::IsScored(distance)) {
            ++unscored;
            return;
        }
        if (min_count == 0 || distance < min) {
            min = distance;
            min_count = 0;
        }
        if (max_count == 0 || distance > max) {
            max = distance;
            max_count = 0;
        }
        min_count += distance == min ? 1 : 0;
        max_count += distance == max ? 1 : 0;
    }
    void Merge(const NegativeExtremes& other) {
        total += other.total;
        unscored += other.unscored;
        if (other.min_count > 0) {
            if (min_count == 0 || other.min < min) {
                min = other.min;
                min_count = other.min_count;
            } else if (other.min == min) {
                min_count += other.min_count;
            }
        }
        if (other.max_count > 0) {
            if (max_count == 0 || other.max > max) {
                max = other.max;
                max_count = other.max_count;
            } else if (other.max == max) {
                max_count += other.max_count;
            }
        }
    }
};

// Offers a candidate to a scan's best match as BestMatchesFromCondensed does, for candidates in
// any order: the smallest distance wins, ties to the smaller scan.
void Offer(BestMatch& m, std::size_t other, double distance) {
    if (distance < m.distance || (distance == m.distance && other < m.match &&
                                  distance != std::numeric_limits<double>::infinity())) {
        m.second_distance = std::min(m.second_distance, m.distance);
        m.distance = distance;
        m.match = other;
    } else {
        m.second_distance = std::min(m.second_distance, distance);
    }
}

void MergeBest(BestMatch& into, const BestMatch& from) {
    if (from.match != kNoScan) {
        Offer(into, from.match, from.distance);
    } else {
        into.second_distance = std::min(into.second_distance, from.distance);
    }
    into.second_distance = std::min(into.second_distance, from.second_distance);
}

// What a first-pass sink holds besides its batches, and what the first pass merges them into.
struct FirstPassTally {
    std::vector<BestMatch> best;  // per scan
    std::size_t distinct = 0;     // distances seen first by this tally's sinks
    NegativeExtremes all;
    NegativeExtremes train;
    NegativeExtremes test;

    explicit FirstPassTally(std::size_t scans) : best(scans, BestMatch{}) {}
    void Merge(const FirstPassTally& other) {
        for (std::size_t k = 0; k < best.size(); ++k) MergeBest(best[k], other.best[k]);
        distinct += other.distinct;
        all.Merge(other.all);
        train.Merge(other.train);
        test.Merge(other.test);
    }
};

// What the second pass counts, per sink and merged.
struct SecondPassTally {
    std::vector<std::uint64_t> fine;            // negatives by key in the target buckets
    std::vector<std::uint64_t> from_threshold;  // as in ConfusionsAt
    std::uint64_t test_at_learnt = 0;           // test negatives <= the learnt threshold

    void Merge(const SecondPassTally& other) {
        for (std::size_t k = 0; k < fine.size(); ++k) fine[k] += other.fine[k];
        for (std::size_t k = 0; k < from_threshold.size(); ++k)
            from_threshold[k] += other.from_threshold[k];
        test_at_learnt += other.test_at_learnt;
    }
};

}  // namespace

// ---- Fixed before the first pass ----------------------------------------------------------

struct StreamedPairwise::Context {
    const GroundTruth* truth = nullptr;
    StreamedRequest request;
    std::uint64_t positive_count = 0;
    std::size_t first_test_scan = 0;  // the test part: pairs with j >= it
    PositiveLevels all;
    PositiveLevels train;
    std::vector<double> ascending_thresholds;
    std::vector<std::size_t> threshold_order;

    bool Learning() const { return request.learning.has_value(); }
    bool InTest(std::size_t j) const { return j >= first_test_scan; }
};

// ---- The first pass -----------------------------------------------------------------------

// All that the first pass found, handed whole (moved) to the second pass and from there to the
// result: a field added here reaches both without a line that copies it.
struct StreamedPairwise::FirstPassResult {
    FirstPassTally tally;
    std::vector<std::uint64_t> coarse;  // negatives by the top bits of their key
    SlotCounts all_slots;               // negatives in the slots between all.keys
    SlotCounts train_slots;             // training negatives between train.keys
};

// Counts every negative in its slot and coarse bucket, and keeps the best matches, the
// extremes and the distinct distances. The sinks add their located batches straight into the
// slots and the coarse histogram, under `counting_`: one copy of the O(positives) slots, not one
// a thread; the rest they keep to themselves until Merge.
class StreamedPairwise::FirstPass {
public:
    explicit FirstPass(const Context& context)
        : context_(context), result_{FirstPassTally(context.truth->size()), {}, {}, {}} {
        result_.coarse.assign(kCoarseBuckets, 0);
        result_.all_slots.Assign(context.all.SlotCount());
        if (context.Learning()) result_.train_slots.Assign(context.train.SlotCount());
    }
    const Context& context() const { return context_; }
    // True when no pair had this distance before: fetch_or tells exactly one thread.
    bool MarkDistinct(std::uint32_t key) const {
        std::atomic_ref<std::uint64_t> word(bitmap_.get()[key >> 6]);
        const std::uint64_t bit = std::uint64_t{1} << (key & 63u);
        if ((word.load(std::memory_order_relaxed) & bit) != 0) return false;
        return (word.fetch_or(bit, std::memory_order_relaxed) & bit) == 0;
    }
    // Adds located batches of a sink; thread-safe.
    void AddBatches(const std::vector<std::uint64_t>& all, const std::vector<std::uint64_t>& train,
                    const std::vector<std::uint64_t>& coarse) {
        const std::lock_guard<std::mutex> lock(counting_);
        AddLocated(all, result_.all_slots);
        AddLocated(train, result_.train_slots);
        for (const std::uint64_t entry : coarse)
            result_.coarse[entry >> kCountBits] += entry & kCountMask;
    }
    void Merge(const FirstPassTally& tally) { result_.tally.Merge(tally); }
    bool Empty() const { return context_.positive_count + result_.tally.all.total == 0; }
    FirstPassResult Finish() && { return std::move(result_); }

private:
    const Context& context_;
    std::unique_ptr<std::uint64_t, FreeDeleter> bitmap_ = NewBitmap();
    std::mutex counting_;
    FirstPassResult result_;
};

class StreamedPairwise::FirstSink {
public:
    explicit FirstSink(FirstPass& pass) : pass_(&pass), tally_(pass.context().truth->size()) {
        pending_all_.reserve(kPending);
        if (pass.context().Learning()) pending_train_.reserve(kPending);
    }
    void Add(std::size_t i, std::size_t j, float distance) {
        const Context& c = pass_->context();
        if (!c.truth->Comparable(i, j)) return;
        CheckNotNan(i, j, distance);
        Offer(tally_.best[i], j, distance);
        Offer(tally_.best[j], i, distance);
        if (!c.truth->IsLoop(i, j)) {
            AddNegative(j, distance);
        } else if (detail::IsScored(distance) && pass_->MarkDistinct(OrderKey(distance))) {
            ++tally_.distinct;  // the negatives' distances are marked when counted (Flush)
        }
    }
    // Counts what the sink still holds and hands its tally to the pass.
    void MergeInto(FirstPass& pass) {
        Flush();
        pass.Merge(tally_);
    }

private:
    void AddNegative(std::size_t j, float distance) {
        const Context& c = pass_->context();
        // Counted in sorted batches: one random access a negative into the slots cost most of
        // the time when they outgrow the cache.
        tally_.all.Add(distance);
        const bool scored = detail::IsScored(distance);
        if (scored) pending_all_.push_back(OrderKey(distance));
        if (c.Learning()) {
            const bool in_test = c.InTest(j);
            (in_test ? tally_.test : tally_.train).Add(distance);
            if (scored && !in_test) pending_train_.push_back(OrderKey(distance));
        }
        if (pending_all_.size() >= kPending || pending_train_.size() >= kPending) Flush();
    }
    void Flush() {
        const Context& c = pass_->context();
        RadixSort(pending_all_, scratch_);
        RadixSort(pending_train_, scratch_);
        // Sorting and locating outside the lock; under it only the additions, in ascending order.
        located_coarse_.clear();
        LocateSortedKeys(
            pending_all_, c.all, located_all_, [&](std::uint32_t key, std::uint64_t count) {
                const std::uint64_t bucket = key >> kFineBits;
                if (!located_coarse_.empty() && (located_coarse_.back() >> kCountBits) == bucket) {
                    located_coarse_.back() += count;
                } else {
                    located_coarse_.push_back((bucket << kCountBits) | count);
                }
                if (pass_->MarkDistinct(key)) ++tally_.distinct;
            });
        LocateSortedKeys(pending_train_, c.train, located_train_,
                         [](std::uint32_t, std::uint64_t) {});
        pass_->AddBatches(located_all_, located_train_, located_coarse_);
        pending_all_.clear();
        pending_train_.clear();
    }

    FirstPass* pass_;
    FirstPassTally tally_;
    std::vector<std::uint32_t> pending_all_;    // keys of negatives to count
    std::vector<std::uint32_t> pending_train_;  // of training negatives
    std::vector<std::uint32_t> scratch_;
    // A sorted batch located outside the lock, (slot or bucket << kCountBits) | count.
    std::vector<std::uint64_t> located_all_;
    std::vector<std::uint64_t> located_train_;
    std::vector<std::uint64_t> located_coarse_;
};

// ---- Between the passes, and after them ---------------------------------------------------

namespace {

// Walks the sweep's steps: for each D_k the run of negatives below it (slot 2k), then the
// positives and negatives at it (slot 2k + 1); finally the run above all (slot 2U).
template <class Run, class AtLevel>
void ForEachStep(const PositiveLevels& levels, const SlotCounts& slots, Run run, AtLevel at_level) {
    std::uint64_t tp = 0;
    std::uint64_t fp = 0;
    for (std::size_t k = 0; k <= levels.size(); ++k) {
        const std::uint64_t below = slots[2 * k];
        run(k, tp, fp, below);
        fp += below;
        if (k == levels.size()) break;
        const std::uint64_t positives = levels.Count(k);
        const std::uint64_t at = slots[2 * k + 1];
        at_level(k, tp, fp, positives, at);
        tp += positives;
        fp += at;
    }
}

// The smallest fp in [low, high] whose curve point lies in a bucket >= `bucket`; high when none.
std::uint64_t FirstFpInBucket(const detail::CurveThinner& thinner, double bucket, std::uint64_t tp,
                              std::uint64_t low, std::uint64_t high, std::uint64_t positives,
                              std::uint64_t negatives) {
    while (low < high) {
        const std::uint64_t mid = low + (high - low) / 2;
        const CurvePoint p = detail::MakePoint(0.0, ConfusionOf(tp, mid, positives, negatives));
        if (thinner.Bucket(p) >= bucket) {
            high = mid;
        } else {
            low = mid + 1;
        }
    }
    return low;
}

struct Optima {
    BestThreshold mcc;
    BestThreshold f1;
};

// The optima over the sweep's points at the positives' distances and its first and last points:
// see the top of this file for why the points between two positives' distances cannot win.
Optima BestOf(const PositiveLevels& levels, const SlotCounts& slots,
              const NegativeExtremes& negatives) {
    const std::uint64_t positives_n = levels.total;
    const std::uint64_t negatives_n = negatives.total;
    const Confusion start = ConfusionOf(0, 0, positives_n, negatives_n);
    const double minus_inf = -std::numeric_limits<double>::infinity();
    Optima best{{minus_inf, Mcc(start), start}, {minus_inf, F1(start), start}};
    bool have_mcc = false;
    bool have_f1 = false;
    const auto consider = [&](double threshold, std::uint64_t tp, std::uint64_t fp) {
        const Confusion c = ConfusionOf(tp, fp, positives_n, negatives_n);
        detail::KeepBest(best.mcc, have_mcc, Mcc(c), threshold, c);
        detail::KeepBest(best.f1, have_f1, F1(c), threshold, c);
    };
    if (slots.front() > 0) consider(negatives.min, 0, negatives.min_count);
    std::uint64_t scored_positives = 0;
    ForEachStep(
        levels, slots, [](std::size_t, std::uint64_t, std::uint64_t, std::uint64_t) {},
        [&](std::size_t k, std::uint64_t tp, std::uint64_t fp, std::uint64_t pos,
            std::uint64_t neg) {
            consider(levels.Distance(k), tp + pos, fp + neg);
            scored_positives = tp + pos;
        });
    if (slots.back() > 0)
        consider(negatives.max, scored_positives, negatives_n - negatives.unscored);
    return best;
}

}  // namespace

// ---- The second pass ----------------------------------------------------------------------

// Counts the negatives of the coarse buckets that hold a wanted rank key by key, the negatives
// from each fixed threshold on, and the test negatives at the learnt threshold; then resolves
// the ranks and computes the result from both passes' counts.
class StreamedPairwise::SecondPass {
public:
    SecondPass(const Context& context, FirstPassResult first)
        : context_(context), first_(std::move(first)) {
        LocateRanks();
        if (const auto t = Transfer(0)) learnt_threshold_ = t->threshold;
        tally_ = NewTally();
    }
    const Context& context() const { return context_; }
    SecondPassTally NewTally() const {
        return {std::vector<std::uint64_t>(tables_ * kFineKeys, 0),
                std::vector<std::uint64_t>(context_.ascending_thresholds.size() + 1, 0), 0};
    }
    void Count(SecondPassTally& tally, std::size_t j, float distance) const {
        if (!detail::IsScored(distance)) return;
        const std::uint32_t key = OrderKey(distance);
        const std::int32_t table = fine_of_bucket_[key >> kFineBits];
        if (table >= 0)
            ++tally.fine[static_cast<std::size_t>(table) * kFineKeys + (key & (kFineKeys - 1))];
        const std::vector<double>& thresholds = context_.ascending_thresholds;
        const auto first =
            std::lower_bound(thresholds.begin(), thresholds.end(), static_cast<double>(distance));
        ++tally.from_threshold[static_cast<std::size_t>(first - thresholds.begin())];
        if (context_.Learning() && context_.InTest(j) && learnt_threshold_ &&
            static_cast<double>(distance) <= *learnt_threshold_)
            ++tally.test_at_learnt;
    }
    void Merge(const SecondPassTally& tally) { tally_.Merge(tally); }
    void ResolveQueries();
    StreamedResult Result() const;

private:
    void LocateRanks();
    void SweepAll(StreamedResult& result) const;
    std::optional<ThresholdTransfer> Transfer(std::uint64_t test_at_learnt) const;

    const Context& context_;
    const FirstPassResult first_;
    std::vector<std::int32_t> fine_of_bucket_;  // table of a coarse bucket, or -1
    std::size_t tables_ = 0;
    std::vector<RankQuery> queries_;
    std::optional<double> learnt_threshold_;
    SecondPassTally tally_;
};

class StreamedPairwise::SecondSink {
public:
    explicit SecondSink(const SecondPass& pass) : pass_(&pass), tally_(pass.NewTally()) {}
    void Add(std::size_t i, std::size_t j, float distance) {
        const Context& c = pass_->context();
        if (!c.truth->Comparable(i, j)) return;
        CheckNotNan(i, j, distance);
        if (!c.truth->IsLoop(i, j)) pass_->Count(tally_, j, distance);
    }
    void MergeInto(SecondPass& pass) const { pass.Merge(tally_); }

private:
    const SecondPass* pass_;
    SecondPassTally tally_;
};

void StreamedPairwise::SecondPass::LocateRanks() {
    const std::uint64_t positives_n = context_.positive_count;
    const std::uint64_t negatives_n = first_.tally.all.total;
    const detail::CurveThinner thinner(context_.request.pairwise.max_curve_points);
    std::vector<std::uint64_t> ranks;
    // Every rank that can start a new bucket inside a run (see SweepAll).
    ForEachStep(
        context_.all, first_.all_slots,
        [&](std::size_t, std::uint64_t tp, std::uint64_t fp, std::uint64_t count) {
            if (count == 0) return;
            const auto bucket_at = [&](std::uint64_t f) {
                return thinner.Bucket(
                    detail::MakePoint(0.0, ConfusionOf(tp, f, positives_n, negatives_n)));
            };
            for (double b = bucket_at(fp) + 1; b <= bucket_at(fp + count); ++b) {
                ranks.push_back(
                    FirstFpInBucket(thinner, b, tp, fp + 1, fp + count, positives_n, negatives_n));
            }
        },
        [](std::size_t, std::uint64_t, std::uint64_t, std::uint64_t, std::uint64_t) {});
    ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
    // Locate each rank's coarse bucket.
    fine_of_bucket_.assign(kCoarseBuckets, -1);
    std::uint64_t before = 0;
    std::size_t next = 0;
    for (std::size_t bucket = 0; bucket < kCoarseBuckets && next < ranks.size(); ++bucket) {
        const std::uint64_t count = first_.coarse[bucket];
        for (; next < ranks.size() && ranks[next] <= before + count; ++next) {
            if (fine_of_bucket_[bucket] < 0)
                fine_of_bucket_[bucket] = static_cast<std::int32_t>(tables_++);
            queries_.push_back(
                {ranks[next], static_cast<std::uint32_t>(bucket), ranks[next] - before, 0.0f, 0});
        }
        before += count;
    }
}

void StreamedPairwise::SecondPass::ResolveQueries() {
    std::uint64_t before = 0;
    std::uint32_t summed_to = 0;  // coarse buckets [0, summed_to) are in `before`
    for (RankQuery& q : queries_) {
        for (; summed_to < q.bucket; ++summed_to) before += first_.coarse[summed_to];
        const std::uint64_t* table =
            tally_.fine.data() + static_cast<std::size_t>(fine_of_bucket_[q.bucket]) * kFineKeys;
        std::uint64_t cumulative = 0;
        std::size_t key = 0;
        for (; key < kFineKeys; ++key) {
            cumulative += table[key];
            if (cumulative >= q.rank_in_bucket) break;
        }
        q.value = FromKey((q.bucket << kFineBits) | static_cast<std::uint32_t>(key));
        q.at_most = before + cumulative;
    }
}

void StreamedPairwise::SecondPass::SweepAll(StreamedResult& result) const {
    PairwiseEvaluation& e = result.pairwise;
    const PositiveLevels& all = context_.all;
    const SlotCounts& all_slots = first_.all_slots;
    const std::uint64_t positives_n = context_.positive_count;
    const std::uint64_t negatives_n = first_.tally.all.total;
    e.pairs = positives_n + negatives_n;
    e.positives = positives_n;
    e.negatives = negatives_n;
    e.distinct_thresholds = first_.tally.distinct;
    const auto point_at = [&](double threshold, std::uint64_t tp, std::uint64_t fp) {
        return detail::MakePoint(threshold, ConfusionOf(tp, fp, positives_n, negatives_n));
    };
    e.curve.push_back(point_at(-std::numeric_limits<double>::infinity(), 0, 0));
    detail::CurveThinner thinner(context_.request.pairwise.max_curve_points);
    detail::AreaSum area;
    const std::size_t levels = all.size();
    const bool ends_in_run = all_slots.back() > 0;
    std::size_t next_query = 0;
    const auto run = [&](std::size_t k, std::uint64_t tp, std::uint64_t fp, std::uint64_t count) {
        if (count == 0) return;
        area.Step(count, tp, tp);
        const std::uint64_t end = fp + count;
        while (thinner.Bucket(point_at(0.0, tp, end)) > thinner.last_bucket()) {
            const std::uint64_t rank = FirstFpInBucket(thinner, thinner.last_bucket() + 1, tp,
                                                       fp + 1, end, positives_n, negatives_n);
            while (next_query < queries_.size() && queries_[next_query].rank < rank) ++next_query;
            if (next_query == queries_.size() || queries_[next_query].rank != rank)
                throw core::Error("streamed evaluation: a curve point was not located");
            const RankQuery& q = queries_[next_query];
            if (k == levels && q.at_most == end) break;  // the last point, kept below
            const CurvePoint point = point_at(q.value, tp, q.at_most);
            thinner.Keep(point);
            e.curve.push_back(point);
            fp = q.at_most;
        }
        if (k == levels) e.curve.push_back(point_at(first_.tally.all.max, tp, end));
    };
    const auto at_level = [&](std::size_t k, std::uint64_t tp, std::uint64_t fp, std::uint64_t pos,
                              std::uint64_t neg) {
        area.Step(neg, tp, tp + pos);
        const CurvePoint point = point_at(all.Distance(k), tp + pos, fp + neg);
        const bool last = k + 1 == levels && !ends_in_run;
        if (last || thinner.Keep(point)) e.curve.push_back(point);
    };
    ForEachStep(all, all_slots, run, at_level);
    if (positives_n > 0 && negatives_n > 0) e.roc_auc = area.Area(positives_n, negatives_n);
    const Optima best = BestOf(all, all_slots, first_.tally.all);
    e.best_mcc = best.mcc;
    e.best_f1 = best.f1;
    result.optimum_exact = !(best.mcc.score < 0.0);
}

// The threshold learnt on the training part and its scores on the test part, whose negatives
// at or below it are `test_at_learnt` (0 before the second pass, which counts them).
std::optional<ThresholdTransfer> StreamedPairwise::SecondPass::Transfer(
    std::uint64_t test_at_learnt) const {
    if (!context_.Learning()) return std::nullopt;
    const FirstPassTally& t = first_.tally;
    const std::uint64_t test_positives = context_.positive_count - context_.train.total;
    const std::uint64_t train_pairs = context_.train.total + t.train.total;
    const std::uint64_t test_pairs = test_positives + t.test.total;
    if (train_pairs == 0 || test_pairs == 0) return std::nullopt;
    if (context_.train.size() == 0 && t.train.min_count == 0) return std::nullopt;
    const Optima best = BestOf(context_.train, first_.train_slots, t.train);
    const Criterion criterion = context_.request.learning->criterion;
    const BestThreshold& chosen = criterion == Criterion::kMcc ? best.mcc : best.f1;
    // The test part's positives are those of the whole sequence minus the training part's.
    const std::uint64_t tp =
        context_.all.AtMost(chosen.threshold) - context_.train.AtMost(chosen.threshold);
    return TransferOf(criterion, chosen,
                      ConfusionOf(tp, test_at_learnt, test_positives, t.test.total));
}

StreamedResult StreamedPairwise::SecondPass::Result() const {
    StreamedResult result;
    SweepAll(result);
    result.learnt = Transfer(tally_.test_at_learnt);
    result.best_matches = first_.tally.best;
    // ConfusionsAt: positives directly, negatives from the second pass's counts.
    const std::uint64_t negatives = first_.tally.all.total;
    const std::uint64_t positives = context_.positive_count;
    const std::vector<double>& thresholds = context_.ascending_thresholds;
    result.at_thresholds.resize(thresholds.size());
    std::uint64_t fp = 0;
    for (std::size_t r = 0; r < thresholds.size(); ++r) {
        fp += tally_.from_threshold[r];
        const std::uint64_t tp = context_.all.AtMost(thresholds[r]);
        result.at_thresholds[context_.threshold_order[r]] =
            ConfusionOf(tp, fp, positives, negatives);
    }
    return result;
}

// ---- StreamedPairwise -------------------------------------------------------------------------

std::vector<float> ScorePositives(const GroundTruth& truth, const PairDistance& distance) {
    std::vector<float> positives;
    positives.reserve(truth.loop_count);
    truth.ForEachLoop([&](const LoopPair& loop) {
        const float d = distance(loop.i, loop.j);
        CheckNotNan(loop.i, loop.j, d);
        positives.push_back(d);
    });
    return positives;
}

namespace {

// Throws for a NaN among the positives, naming its pair (found by enumerating them again).
void CheckPositives(const GroundTruth& truth, const std::vector<float>& positives) {
    if (positives.size() != truth.loop_count) {
        throw core::ConfigError("pair-wise evaluation: " + std::to_string(positives.size()) +
                                " positive distances for " + std::to_string(truth.loop_count) +
                                " positive pairs");
    }
    if (std::none_of(positives.begin(), positives.end(), [](float d) { return std::isnan(d); }))
        return;
    std::size_t k = 0;
    truth.ForEachLoop([&](const LoopPair& loop) { CheckNotNan(loop.i, loop.j, positives[k++]); });
}

// The distances of the positives of the training part (j before first_test_scan), in the
// order of `positives` (GroundTruth::ForEachLoop's).
std::vector<float> TrainingPositives(const GroundTruth& truth, const std::vector<float>& positives,
                                     std::size_t first_test_scan) {
    std::vector<float> train;
    std::size_t k = 0;
    truth.ForEachLoop([&](const LoopPair& loop) {
        if (loop.j < first_test_scan) train.push_back(positives[k]);
        ++k;
    });
    return train;
}

}  // namespace

StreamedPairwise::Sink::Sink(std::unique_ptr<FirstSink> first, std::unique_ptr<SecondSink> second)
    : first_(std::move(first)), second_(std::move(second)) {}
StreamedPairwise::Sink::Sink(Sink&&) noexcept = default;
StreamedPairwise::Sink& StreamedPairwise::Sink::operator=(Sink&&) noexcept = default;
StreamedPairwise::Sink::~Sink() = default;

void StreamedPairwise::Sink::Add(std::size_t i, std::size_t j, float distance) {
    if (first_) {
        first_->Add(i, j, distance);
    } else {
        second_->Add(i, j, distance);
    }
}

StreamedPairwise::StreamedPairwise(const GroundTruth& truth, std::vector<float> positives,
                                   StreamedRequest request) {
    request.pairwise.Validate();
    if (request.pairwise.max_curve_points == 0) {
        throw core::ConfigError(
            "pairwise.max_curve_points must be >= 3 for the streamed evaluation: keeping every "
            "point needs every distance in memory");
    }
    if (request.learning) request.learning->Validate();
    for (const double t : request.thresholds) {
        if (std::isnan(t)) throw core::ConfigError("evaluation threshold must not be NaN");
    }
    if (truth.size() > std::numeric_limits<std::uint32_t>::max())
        throw core::ConfigError("pair-wise evaluation: more than 2^32 scans");
    CheckPositives(truth, positives);
    auto context = std::make_unique<Context>();
    Context& c = *context;
    c.truth = &truth;
    c.request = std::move(request);
    c.positive_count = positives.size();
    if (c.request.learning) {
        c.first_test_scan = static_cast<std::size_t>(
            std::llround(c.request.learning->train_fraction * static_cast<double>(truth.size())));
        std::vector<float> train = TrainingPositives(truth, positives, c.first_test_scan);
        c.train = LevelsOf(train);
    }
    c.all = LevelsOf(positives);
    positives = std::vector<float>();  // the levels hold what is needed of them
    const std::vector<double>& thresholds = c.request.thresholds;
    c.threshold_order.resize(thresholds.size());
    for (std::size_t k = 0; k < thresholds.size(); ++k) c.threshold_order[k] = k;
    std::sort(c.threshold_order.begin(), c.threshold_order.end(),
              [&](std::size_t a, std::size_t b) { return thresholds[a] < thresholds[b]; });
    for (const std::size_t k : c.threshold_order) c.ascending_thresholds.push_back(thresholds[k]);
    context_ = std::move(context);
    first_ = std::make_unique<FirstPass>(*context_);
}

StreamedPairwise::~StreamedPairwise() = default;

int StreamedPairwise::pass() const { return first_ ? 1 : finished_ ? 3 : 2; }

StreamedPairwise::Sink StreamedPairwise::NewSink() const {
    if (first_) return Sink(std::make_unique<FirstSink>(*first_), nullptr);
    if (finished_) throw core::Error("streamed evaluation: NewSink() after both passes ended");
    return Sink(nullptr, std::make_unique<SecondSink>(*second_));
}

void StreamedPairwise::Merge(Sink& sink) {
    if (first_ && sink.first_) {
        sink.first_->MergeInto(*first_);
    } else if (second_ && !finished_ && sink.second_) {
        sink.second_->MergeInto(*second_);
    } else {
        throw core::Error("streamed evaluation: Merge() of a sink of another pass");
    }
}

void StreamedPairwise::EndPass() {
    if (first_) {
        if (first_->Empty())
            throw core::EmptyInputError("pair-wise evaluation: no pairs to evaluate");
        // The first pass's findings move whole into the second.
        second_ = std::make_unique<SecondPass>(*context_, std::move(*first_).Finish());
        first_.reset();
    } else if (!finished_) {
        second_->ResolveQueries();
        finished_ = true;
    }
}

StreamedResult StreamedPairwise::Result() const {
    if (!finished_) throw core::Error("streamed evaluation: Result() before both passes ended");
    return second_->Result();
}

StreamedResult StreamSerially(StreamedPairwise& evaluation, std::size_t n,
                              const PairDistance& distance) {
    while (!evaluation.finished()) {
        StreamedPairwise::Sink sink = evaluation.NewSink();
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = i + 1; j < n; ++j) sink.Add(i, j, distance(i, j));
        }
        evaluation.Merge(sink);
        evaluation.EndPass();
    }
    return evaluation.Result();
}

}  // namespace lidarloop::eval
