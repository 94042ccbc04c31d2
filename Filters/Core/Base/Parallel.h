// Injectable parallel-for, so that the algorithms stay free of VTK: the VTK wrappers pass one
// built on vtkSMPTools, unit tests use the serial default. Every loop handed to it writes only to
// its own indices, so results do not depend on how the range is split (bit-identical outputs
// whatever the thread count).
#pragma once
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>

namespace featuremesh
{
using RangeFunction = std::function<void(std::int64_t begin, std::int64_t end)>;
using ParallelFor = std::function<void(std::int64_t n, std::int64_t grain, const RangeFunction&)>;

inline ParallelFor SerialFor()
{
  return [](std::int64_t n, std::int64_t, const RangeFunction& f) {
    if (n > 0)
    {
      f(0, n);
    }
  };
}

// Progress in [0,1]; returns false when the caller asked to abort. Called on the caller's thread.
using ProgressFunction = std::function<bool(double)>;
inline ProgressFunction NoProgress()
{
  return [](double) { return true; };
}

// `body` over [0, n) in up to 8 sequential batches, each run by `parallel`, with progress
// reported between batches on this thread; false when progress asked to abort.
inline bool BatchedFor(std::int64_t n, std::int64_t grain, const ParallelFor& parallel, const ProgressFunction& progress,
  const RangeFunction& body)
{
  // Up to 8 batches, each of 64 grains at least: VTK 9.2's STDThread backend starts its threads for
  // every loop, which costs more than a small batch's work.
  const std::int64_t batches = std::max<std::int64_t>(1, std::min<std::int64_t>(8, n / (64 * std::max<std::int64_t>(grain, 1))));
  const std::int64_t size = std::max<std::int64_t>(1, (n + batches - 1) / batches);
  for (std::int64_t b = 0; b < n; b += size)
  {
    const std::int64_t e = std::min(n, b + size);
    parallel(e - b, grain, [&](std::int64_t s, std::int64_t t) { body(b + s, b + t); });
    if (!progress(static_cast<double>(e) / static_cast<double>(n)))
    {
      return false;
    }
  }
  return true;
}

// Progress of a sub-range [begin, end] of a caller's progress.
inline ProgressFunction SubProgress(const ProgressFunction& progress, double begin, double end)
{
  return [=](double t) { return progress(begin + (end - begin) * t); };
}

// Runs `task` (a library call that has no progress or abort of its own: max-flow, TetGen) on its
// own thread and reports progress on this one every `period` until it ends; the reported fraction
// approaches 1 as time passes. Returns true with the task's result, rethrowing what it threw; or
// false as soon as `progress` asks to abort, leaving the task to finish unobserved on its detached
// thread, so `task` must own (capture by value) everything it touches.
template <typename Result>
bool RunWithHeartbeat(std::function<Result()> task, const ProgressFunction& progress, Result& result,
  std::chrono::milliseconds period = std::chrono::milliseconds(100))
{
  struct State
  {
    std::mutex Lock;
    std::condition_variable Done;
    bool Finished = false;
    Result Value{};
    std::exception_ptr Error;
  };
  auto state = std::make_shared<State>();
  std::thread([state, task = std::move(task)]() {
    Result value{};
    std::exception_ptr error;
    try
    {
      value = task();
    }
    catch (...)
    {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(state->Lock);
    state->Value = std::move(value);
    state->Error = error;
    state->Finished = true;
    state->Done.notify_all();
  }).detach();
  const auto start = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(state->Lock);
  while (!state->Done.wait_for(lock, period, [&] { return state->Finished; }))
  {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    lock.unlock();
    const bool go = progress(seconds / (seconds + 2.0));
    lock.lock();
    if (!go && !state->Finished)
    {
      return false;
    }
  }
  if (state->Error)
  {
    std::rethrow_exception(state->Error);
  }
  result = std::move(state->Value);
  return true;
}
} // namespace featuremesh
