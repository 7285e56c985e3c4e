#include "lidarshop/inpaint/forward_looking.h"

#include <algorithm>

#include "lidarshop/util/error.h"

namespace lidarshop {

TargetChooser::TargetChooser(const InpaintCanvas& canvas, const InpaintOptions& options,
                             const PatchDifference& difference, PatchSearch& search,
                             const PatchAcceptance* acceptance, bool search_is_exhaustive)
    : canvas_(canvas),
      options_(options),
      difference_(difference),
      search_(search),
      acceptance_(acceptance),
      search_is_exhaustive_(search_is_exhaustive) {}

std::vector<SourceCandidate> TargetChooser::LocalBest(const TargetDifference& difference, Pixel target,
                                                      int count) {
  for (int radius = options_.local_window_radius;; radius *= 2) {
    std::vector<SourceCandidate> best = exhaustive_.FindNear(canvas_, difference, target, count, radius);
    if (static_cast<int>(best.size()) == count || radius >= std::max(canvas_.rows(), canvas_.cols()))
      return best;
  }
}

TargetDecision TargetChooser::Compute(Pixel target) {
  TargetDecision decision;
  decision.target = target;
  const std::unique_ptr<TargetDifference> difference = difference_.ForTarget(canvas_, target);
  if (acceptance_ == nullptr) {
    decision.candidates = search_.Find(canvas_, *difference, target, 1);
    LIDARSHOP_CHECK(!decision.candidates.empty());
    decision.chosen = 0;
    return decision;
  }
  const int count = options_.acceptance_candidates;
  std::vector<SourceCandidate> judged;  // sources already judged (rejected)
  auto try_list = [&](const std::vector<SourceCandidate>& list) {
    for (size_t i = 0; i < list.size(); ++i) {
      const bool seen = std::any_of(judged.begin(), judged.end(),
                                    [&](const SourceCandidate& j) { return j.source == list[i].source; });
      if (seen) continue;
      const AcceptanceVerdict verdict = acceptance_->Judge(canvas_, target, list[i]);
      if (verdict.accepted) {
        decision.candidates = list;
        decision.chosen = static_cast<int>(i);
        decision.verdict = verdict;
        return true;
      }
      if (judged.empty()) decision.verdict = verdict;  // the best candidate's verdict
      judged.push_back(list[i]);
      ++decision.rejected;
    }
    return false;
  };
  std::vector<SourceCandidate> local;
  if (options_.acceptance_local_first) {
    local = LocalBest(*difference, target, count);
    if (try_list(local)) return decision;
  }
  ++global_searches_;
  if (search_is_exhaustive_ && static_cast<int>(local.size()) == count) {
    std::vector<SourceCandidate> all = exhaustive_.FindBelow(
        canvas_, *difference, target, count, local.back().difference, 0, canvas_.rows(), 0, canvas_.cols());
    all.insert(all.end(), local.begin(), local.end());
    MergeCandidates(all, count);
    decision.candidates = std::move(all);
  } else {
    decision.candidates = search_.Find(canvas_, *difference, target, count);
  }
  LIDARSHOP_CHECK(!decision.candidates.empty());
  try_list(decision.candidates);
  if (!decision.passed()) decision.verdict = acceptance_->Judge(canvas_, target, decision.candidates.front());
  return decision;
}

const TargetDecision& TargetChooser::Decide(Pixel target) {
  const int64_t key = canvas_.Index(target.row, target.col);
  auto it = cache_.find(key);
  if (it == cache_.end()) it = cache_.emplace(key, Compute(target)).first;
  return it->second;
}

TargetDecision TargetChooser::Choose(const Front& front) {
  if (acceptance_ == nullptr || options_.lookahead <= 1) {
    const Pixel target = front.Best();
    cache_.erase(canvas_.Index(target.row, target.col));
    return Compute(target);
  }
  // Front pixels by priority (highest first; ties: smallest index, as Front::Best()).
  std::vector<std::pair<double, int64_t>> order;
  order.reserve(front.pixels().size());
  for (const Pixel& p : front.pixels()) order.push_back({-front.Value(p), canvas_.Index(p.row, p.col)});
  std::sort(order.begin(), order.end());
  const TargetDecision* best = nullptr;
  int considered = 0;
  for (const auto& [negative_priority, index] : order) {
    const Pixel p{static_cast<int>(index / canvas_.cols()), static_cast<int>(index % canvas_.cols())};
    auto cached = cache_.find(index);
    if (cached != cache_.end() && !cached->second.passed()) continue;  // deferred
    const TargetDecision& decision = Decide(p);
    ++considered;
    if (decision.passed() && (best == nullptr || decision.verdict.margin > best->verdict.margin))
      best = &decision;
    if (best != nullptr && !options_.lookahead_by_margin) break;
    if (considered >= options_.lookahead) break;
  }
  if (best != nullptr) return *best;
  const int64_t top = order.front().second;
  return Decide({static_cast<int>(top / canvas_.cols()), static_cast<int>(top % canvas_.cols())});
}

void TargetChooser::Filled(Pixel target) {
  const int reach = 2 * canvas_.patch_radius();
  for (auto it = cache_.begin(); it != cache_.end();) {
    const Pixel p = it->second.target;
    if (std::abs(p.row - target.row) <= reach && std::abs(p.col - target.col) <= reach) {
      it = cache_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace lidarshop
