#pragma once
// Work that grows as it is done, shared by threads: an adaptive fit's cores, each of which is
// either fitted or cut into two more cores (FitCurve).

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace cheval::cheb::internal {

/// The threads a `threads` option asks for: 0 is every core the machine has (at least 1).
inline int ThreadCount(int threads) {
  if (threads > 0) return threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

/// Calls process(item, push) on every item of `items` and on every item pushed while doing so,
/// last pushed first (depth first: the pending items stay few). Up to `threads` threads take items,
/// the caller's among them; with one, items are processed in that order on the caller's thread.
/// `process` is called concurrently on different items and must be safe so; `push` may only be
/// called within its own call. The first exception stops the threads from taking more items and
/// is rethrown once they are done. Which thread takes which item is left to chance, so results
/// must not depend on it.
template <typename Item, typename Process>
void DrainWork(std::vector<Item> items, int threads, Process&& process) {
  if (threads <= 1) {
    auto push = [&items](Item item) { items.push_back(std::move(item)); };
    while (!items.empty()) {
      Item item = std::move(items.back());
      items.pop_back();
      process(std::move(item), push);
    }
    return;
  }
  std::mutex mutex;
  std::condition_variable changed;
  int busy = 0;  // items being processed
  std::exception_ptr error;
  auto work = [&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (true) {
      changed.wait(lock, [&] { return !items.empty() || busy == 0 || error; });
      if (error || items.empty()) return;  // empty with nothing in progress: all done
      Item item = std::move(items.back());
      items.pop_back();
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
      if (thrown && !error) error = thrown;
      for (Item& more : pushed) items.push_back(std::move(more));
      changed.notify_all();
    }
  };
  std::vector<std::thread> helpers;
  for (int k = 1; k < threads; ++k) {
    try {
      helpers.emplace_back(work);
    } catch (const std::system_error&) {
      break;  // no more threads to be had: the ones running do the work
    }
  }
  work();
  for (std::thread& helper : helpers) helper.join();
  if (error) std::rethrow_exception(error);
}

/// Calls f(i) for i in [0, count) on up to `threads` threads (the caller's among them); as
/// DrainWork, the first exception is rethrown.
template <typename F>
void ParallelFor(int count, int threads, F&& f) {
  std::vector<int> items(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) items[static_cast<size_t>(count - 1 - i)] = i;  // 0 is taken first
  DrainWork(std::move(items), std::min(threads, count), [&f](int i, auto&&) { f(i); });
}

}  // namespace cheval::cheb::internal
