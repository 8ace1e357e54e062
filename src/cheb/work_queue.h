#pragma once
// Work that grows as it is done, shared by threads: an adaptive fit's cores, each of which is
// either fitted or cut into two more cores (FitCurve).

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace cheval::cheb::internal {

/// The most threads a `threads` option may ask for (CurveOptions::Validate).
constexpr int kMaxThreads = 256;

/// The threads a `threads` option asks for: 0 is every core the machine has (at least 1).
inline int ThreadCount(int threads) {
  if (threads > 0) return std::min(threads, kMaxThreads);
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxThreads);
}

/// Calls process(item, push) on every item of `items` and on every item pushed while doing so,
/// last pushed first (depth first: the pending items stay few). Up to `threads` threads take items,
/// the caller's among them; with one, items are processed in that order on the caller's thread.
/// `process` is called concurrently on different items and must be safe so; `push` may only be
/// called within its own call. Which thread takes which item is left to chance, so results must
/// not depend on it.
///
/// `key(item)` orders items as one thread takes them (smaller first). When items throw, the
/// exception of the item with the smallest key is rethrown once the threads are done: the one a
/// single thread would have met first. After an exception, items ordered after it are dropped
/// and those before it still processed (they may throw first).
template <typename Item, typename Process, typename Key>
void DrainWork(std::vector<Item> items, int threads, Process&& process, Key&& key) {
  if (threads <= 1) {
    auto push = [&items](Item item) { items.push_back(std::move(item)); };
    while (!items.empty()) {
      Item item = std::move(items.back());
      items.pop_back();
      process(std::move(item), push);
    }
    return;
  }
  using KeyType = decltype(key(items.front()));
  std::mutex mutex;
  std::condition_variable changed;
  int busy = 0;  // items being processed
  std::exception_ptr error;
  std::optional<KeyType> error_key;
  // Records an exception of the item keyed `at`; the lock is held.
  auto record = [&](std::exception_ptr thrown, const KeyType& at) {
    if (!error_key || at < *error_key) error = std::move(thrown), error_key = at;
  };
  auto work = [&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (true) {
      changed.wait(lock, [&] { return !items.empty() || busy == 0; });
      if (items.empty()) return;  // and nothing in progress: all done
      Item item = std::move(items.back());
      items.pop_back();
      const KeyType at = key(item);
      if (error_key && !(at < *error_key)) continue;  // one thread would not have come here
      ++busy;
      lock.unlock();
      std::vector<Item> pushed;
      std::exception_ptr thrown;
      try {
        process(std::move(item), [&pushed](Item more) { pushed.push_back(std::move(more)); });
      } catch (...) {
        thrown = std::current_exception();
      }
      lock.lock();
      --busy;
      try {
        if (thrown) {
          record(thrown, at);
        } else {
          for (Item& more : pushed) items.push_back(std::move(more));
        }
      } catch (...) {  // no memory for the pushed items
        record(std::current_exception(), at);
      }
      changed.notify_all();
    }
  };
  std::vector<std::thread> helpers;
  {
    // Every thread started is joined on every way out.
    struct Join {
      std::vector<std::thread>& threads;
      ~Join() {
        for (std::thread& t : threads) t.join();
      }
    } join{helpers};
    try {
      helpers.reserve(static_cast<size_t>(threads - 1));
      for (int k = 1; k < threads; ++k) helpers.emplace_back(work);
    } catch (...) {
      // No more threads to be had: the ones running do the work.
    }
    work();
  }
  if (error) std::rethrow_exception(error);
}

/// Calls f(i) for i in [0, count) on up to `threads` threads (the caller's among them). When calls
/// throw, the exception of the smallest i is rethrown (as with one thread, calls in order).
template <typename F>
void ParallelFor(int count, int threads, F&& f) {
  std::vector<int> items(static_cast<size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i) items[static_cast<size_t>(count - 1 - i)] = i;  // 0 is taken first
  DrainWork(std::move(items), std::min(threads, count), [&f](int i, auto&&) { f(i); }, [](int i) { return i; });
}

/// Calls f(begin, end) on `parts` contiguous ranges that tile [0, count), on as many threads (the
/// caller's among them); exceptions as ParallelFor, the first range first.
template <typename F>
void ParallelRanges(Eigen::Index count, int parts, F&& f) {
  ParallelFor(parts, parts, [&](int part) { f(count * part / parts, count * (part + 1) / parts); });
}

}  // namespace cheval::cheb::internal
