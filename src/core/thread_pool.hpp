// The one process-wide pool of worker threads behind core::parallelChunks
// (core/parallel.hpp), so that the host work of both backends reuses the same
// threads instead of starting fresh ones on every call (issue 16).
//
// Contract:
// - Workers start lazily, never more than the largest number of helpers one
//   call has asked for (threads - 1), and persist between calls. They are
//   joined when the process's statics are destroyed (exit, or dlclose of a
//   Python extension module); a call made after that, e.g. from another
//   static's destructor, runs on the calling thread alone.
// - The pool's memory is never freed, so no late call can touch a dead pool.
// - A fork() child has none of the parent's workers and starts none (POSIX
//   allows a child of a multithreaded process only async-signal-safe calls):
//   its calls run on the calling thread alone, correct but with one thread.
//   A fork must not happen from inside a call's run (its helpers would be
//   gone in the child).
#pragma once

#include <chrono>
#include <cstddef>

namespace rthdist::core {

// One parallel loop, without its callable's type: run(context, begin, end,
// threadIndex) for the chunks [c * chunk, min(count, (c + 1) * chunk)) of
// [0, count).
struct ChunkTask {
    size_t count = 0;
    size_t chunk = 1;
    int threads = 2;  // workers, the caller included: >= 2, at most the chunk count
    void (*run)(void* context, size_t begin, size_t end, int threadIndex) = nullptr;
    void* context = nullptr;
};

// Runs every chunk of `task` exactly once and returns when all have run.
// The calling thread is worker 0 and claims chunks itself; up to
// task.threads - 1 pool workers help with indices 1.. (each index used by one
// thread). Never waits for a worker that is busy elsewhere: only for those
// running this task's chunks, so calls from inside another call's run
// (nested) and from many threads at once always complete.
// Threading: any thread. run must not throw (std::terminate).
void runOnPool(const ChunkTask& task) noexcept;

// How long the pool's waiting threads poll before they sleep (default 200
// us; 0: never). Process-wide; Engine::create sets it from
// Tuning::poolSpinMicros where given. Threading: any thread.
void setPoolSpin(std::chrono::microseconds spin) noexcept;

// Pool workers alive now (diagnostics and tests).
[[nodiscard]] size_t poolWorkerCount() noexcept;
// Pool workers waiting for work now. A process about to fork() can wait until
// this equals poolWorkerCount(): then no worker is starting up or freeing
// memory, which matters under an allocator without fork handlers (GCC 12's
// AddressSanitizer: a child forked while a worker starts hangs in it).
[[nodiscard]] size_t poolIdleWorkerCount() noexcept;

}  // namespace rthdist::core
