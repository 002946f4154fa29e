// SPDX-License-Identifier: MIT
#include "rank_agreement.h"

#include <cstring>
#include <new>

namespace sph {

namespace {

// The first failing rank's status and message, broadcast from it; throws on every rank.
[[noreturn]] void throw_first_failure(const RankTransport& ranks, int64_t first, const Error* own) {
  RankBytes record;
  if (own && ranks.rank() == first) {
    const int32_t status = static_cast<int32_t>(own->status());
    const char* text = own->what();
    record.resize(sizeof status + std::strlen(text));
    std::memcpy(record.data(), &status, sizeof status);
    std::memcpy(record.data() + sizeof status, text, record.size() - sizeof status);
  }
  record = ranks.broadcast(record, static_cast<int>(first));
  if (own) throw AgreedRankFailure(own->status(), own->what());
  int32_t status = static_cast<int32_t>(Status::Internal);
  std::string text = "(no message)";
  if (record.size() >= sizeof status) {
    std::memcpy(&status, record.data(), sizeof status);
    text.assign(reinterpret_cast<const char*>(record.data()) + sizeof status, record.size() - sizeof status);
  }
  throw AgreedRankFailure(static_cast<Status>(status), "rank " + std::to_string(first) + ": " + text);
}

}  // namespace

// A failed rank contributes its rank, one that did not size() + its payload: the minimum is
// below size() exactly when some rank failed, and is then the first that did.
void agree(const RankTransport& ranks, int64_t* payload) {
  int64_t value = ranks.size() + *payload;
  ranks.all_min(&value, 1);
  if (value < ranks.size()) throw_first_failure(ranks, value, nullptr);
  *payload = value - ranks.size();
}

void compare_over_ranks(const RankTransport& ranks, const int64_t* values, int n, bool* same) {
  if (n < 0 || n > 4) throw Error(Status::Internal, "compare_over_ranks: at most 4 values");
  int64_t lo[4], hi[4];
  std::memcpy(lo, values, sizeof(int64_t) * static_cast<size_t>(n));
  std::memcpy(hi, values, sizeof(int64_t) * static_cast<size_t>(n));
  ranks.all_min(lo, n);
  ranks.all_max(hi, n);
  for (int k = 0; k < n; ++k) same[k] = lo[k] == hi[k];
}

void rethrow_agreed(const RankTransport& ranks) {
  try {
    throw;
  } catch (const AgreedRankFailure&) {
    throw;
  } catch (...) {
    const Error own = current_error();
    int64_t first = ranks.rank();
    ranks.all_min(&first, 1);
    throw_first_failure(ranks, first, &own);
  }
}

Error current_error() {
  try {
    throw;
  } catch (const Error& e) {
    return e;
  } catch (const std::bad_alloc&) {
    return Error(Status::OutOfHostMemory, "a host allocation failed");
  } catch (const std::exception& e) {
    return Error(Status::Internal, e.what());
  } catch (...) {
    return Error(Status::Internal, "unknown internal exception");
  }
}

}  // namespace sph
