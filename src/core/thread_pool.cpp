// The process-wide worker pool (core/thread_pool.hpp). A call posts one entry
// asking for `threads - 1` helpers and runs chunks itself at once; idle
// workers take the entry, one helper each, until it has its helpers or the
// caller withdraws it. The state of a call lives in a ChunkJob held by
// shared_ptr, so a helper that arrives after the caller has returned only
// finds that nothing is left (no thread index or no chunk) and never touches
// the caller's callable. A worker only takes work while idle, never while
// waiting inside a nested call, so waits form no cycle. In a fork() child
// every call runs on its caller alone.
//
// Waiting spins before it sleeps: an idle worker polls for a posted call,
// and a caller for its helpers' last chunk, for up to spinTime() before blocking
// on a condition variable. A masks comparison runs ~20 parallel loops back
// to back, and waking a sleeping thread through the kernel costs tens of
// microseconds on a virtual machine's vCPUs (each loop paid it on the H100
// machine's 16 cores: docs/bench/masks).
#include "core/thread_pool.hpp"

#include <pthread.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace rthdist::core {
namespace {

// How long a waiting thread polls before it sleeps: 200 us unless
// setPoolSpin (Tuning::poolSpinMicros) said otherwise (0: never polls;
// benchmarks compare both).
std::atomic<int64_t> g_spinMicros{200};

std::chrono::microseconds spinTime() {
    return std::chrono::microseconds(g_spinMicros.load(std::memory_order_relaxed));
}

void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    asm volatile("yield");
#endif
}

// Polls `ready` until it holds or spinTime() has passed; whether it held.
template <class Ready>
bool spinFor(Ready&& ready) {
    const std::chrono::microseconds spin = spinTime();
    if (spin.count() <= 0) return ready();
    const auto until = std::chrono::steady_clock::now() + spin;
    for (unsigned i = 0;; ++i) {
        if (ready()) return true;
        cpuRelax();
        if ((i & 63u) == 63u && std::chrono::steady_clock::now() >= until) return false;
    }
}

class ChunkJob {
public:
    explicit ChunkJob(const ChunkTask& task)
        : m_task(task), m_chunks((task.count + task.chunk - 1) / task.chunk) {}

    // A pool worker joining: the next thread index (the caller is 0), or
    // nothing when the call already has all its workers.
    void help() {
        const int threadIndex = m_nextThread.fetch_add(1, std::memory_order_relaxed);
        if (threadIndex < m_task.threads) work(threadIndex);
    }

    // Claims and runs chunks until none is left. The chunks run are counted
    // under the mutex, which orders their writes before the caller's return.
    void work(int threadIndex) {
        size_t ran = 0;
        for (;;) {
            const size_t c = m_nextChunk.fetch_add(1, std::memory_order_relaxed);
            if (c >= m_chunks) break;
            const size_t begin = c * m_task.chunk;
            m_task.run(m_task.context, begin, std::min(m_task.count, begin + m_task.chunk), threadIndex);
            ++ran;
        }
        if (ran == 0) return;
        std::lock_guard lock(m_mutex);
        m_done += ran;
        if (m_done == m_chunks) {
            m_allDone.store(true, std::memory_order_release);
            m_finished.notify_all();
        }
    }

    // Waits for the chunks other workers have claimed and not finished yet.
    void waitAll() {
        if (spinFor([this] { return m_allDone.load(std::memory_order_acquire); })) return;
        std::unique_lock lock(m_mutex);
        m_finished.wait(lock, [this] { return m_done == m_chunks; });
    }

private:
    const ChunkTask m_task;
    const size_t m_chunks;
    std::atomic<size_t> m_nextChunk{0};
    std::atomic<int> m_nextThread{1};
    std::mutex m_mutex;
    std::condition_variable m_finished;
    size_t m_done = 0;                   // guarded by m_mutex
    std::atomic<bool> m_allDone{false};  // m_done == m_chunks, for spinFor
};

// A posted call and how many helpers it still asks for.
struct Posting {
    std::shared_ptr<ChunkJob> job;
    size_t helpers = 0;
};

class WorkerPool {
public:
    // False once the pool has shut down, and in a fork() child: the caller
    // then works alone.
    bool post(const std::shared_ptr<ChunkJob>& job, size_t helpers) {
        {
            std::lock_guard lock(m_mutex);
            if (m_stopping || m_forkedChild) return false;
            m_queue.push_back({job, helpers});
            m_queued.store(m_queue.size(), std::memory_order_relaxed);
            m_wanted += helpers;
            m_limit = std::max(m_limit, helpers);
            // Idle workers first; new ones only while the posted calls want
            // more than are idle, up to the most helpers one call asked for.
            while (m_workers.size() < m_limit && m_workers.size() - m_busy < m_wanted) {
                if (!startWorker()) break;
            }
        }
        if (helpers == 1) {
            m_wake.notify_one();
        } else {
            m_wake.notify_all();
        }
        return true;
    }

    // The caller has claimed every chunk: helpers that have not taken the
    // call yet are no longer wanted.
    void withdraw(const ChunkJob* job) {
        std::lock_guard lock(m_mutex);
        const auto it = std::find_if(m_queue.begin(), m_queue.end(),
                                     [job](const Posting& p) { return p.job.get() == job; });
        if (it == m_queue.end()) return;
        m_wanted -= it->helpers;
        m_queue.erase(it);
        m_queued.store(m_queue.size(), std::memory_order_relaxed);
    }

    size_t workerCount() {
        std::lock_guard lock(m_mutex);
        return m_forkedChild ? 0 : m_workers.size();
    }

    size_t idleWorkerCount() {
        std::lock_guard lock(m_mutex);
        return m_forkedChild ? 0 : m_idle;
    }

    // At static destruction: stop taking calls and join the workers (a
    // worker finishes the chunk it runs; the callers finish the rest).
    void shutdown() {
        std::vector<std::thread> workers;
        {
            std::lock_guard lock(m_mutex);
            m_stopping = true;
            m_stopFlag.store(true, std::memory_order_relaxed);
            if (m_forkedChild) return;  // the handles name the parent's threads
            m_queue.clear();
            m_queued.store(0, std::memory_order_relaxed);
            m_wanted = 0;
            workers.swap(m_workers);
        }
        m_wake.notify_all();
        for (std::thread& w : workers) {
            if (w.get_id() == std::this_thread::get_id()) {
                w.detach();  // exit() called from inside a chunk
            } else {
                w.join();
            }
        }
    }

    // fork(): the pool's mutex is held across it, so the child never
    // inherits it locked by a thread that is not there.
    void beforeFork() { m_mutex.lock(); }
    void afterForkInParent() { m_mutex.unlock(); }
    // In the child only the forking thread exists. POSIX allows a child of a
    // multithreaded process only async-signal-safe calls, so the child
    // starts no threads and allocates nothing here: its calls run on the
    // calling thread, and the workers' handles (threads that are gone, which
    // can be neither joined nor destroyed) stay in the never-freed pool.
    void afterForkInChild() {
        m_forkedChild = true;
        m_mutex.unlock();
    }

private:
    // Called with m_mutex held. False when the system has no thread to give.
    bool startWorker() {
        try {
            m_workers.emplace_back([this] { workerLoop(); });
            return true;
        } catch (const std::system_error&) {
            return false;
        }
    }

    void workerLoop() {
        std::unique_lock lock(m_mutex);
        for (;;) {
            if (m_queue.empty() && !m_stopping) {  // the next call may come at once
                lock.unlock();
                spinFor([this] {
                    return m_queued.load(std::memory_order_relaxed) != 0 ||
                           m_stopFlag.load(std::memory_order_relaxed);
                });
                lock.lock();
            }
            ++m_idle;
            m_wake.wait(lock, [this] { return m_stopping || !m_queue.empty(); });
            --m_idle;
            if (m_stopping) return;
            Posting& front = m_queue.front();
            std::shared_ptr<ChunkJob> job = front.job;
            --m_wanted;
            if (--front.helpers == 0) {
                m_queue.pop_front();
                m_queued.store(m_queue.size(), std::memory_order_relaxed);
            }
            ++m_busy;
            lock.unlock();
            job->help();
            job.reset();
            lock.lock();
            --m_busy;
        }
    }

    std::mutex m_mutex;
    std::condition_variable m_wake;
    std::deque<Posting> m_queue;          // calls still asking for helpers
    std::atomic<size_t> m_queued{0};      // m_queue.size(), polled by spinning workers
    std::atomic<bool> m_stopFlag{false};  // m_stopping, polled by spinning workers
    std::vector<std::thread> m_workers;
    size_t m_busy = 0;    // workers inside a call
    size_t m_idle = 0;    // workers waiting for work
    size_t m_wanted = 0;  // helpers the queue still asks for
    size_t m_limit = 0;   // most helpers one call has asked for
    bool m_stopping = false;
    bool m_forkedChild = false;  // this process is a fork() child: no workers
};

WorkerPool& pool();

// Joins the workers when the statics of the process (or of the module that
// holds this library) are destroyed; the pool itself stays valid.
class PoolShutdown {
public:
    PoolShutdown() = default;
    PoolShutdown(const PoolShutdown&) = delete;
    PoolShutdown& operator=(const PoolShutdown&) = delete;
    ~PoolShutdown() { pool().shutdown(); }
};

WorkerPool& pool() {
    static WorkerPool* const instance = [] {
        auto* p = new WorkerPool;  // never freed: see thread_pool.hpp
        pthread_atfork([] { pool().beforeFork(); }, [] { pool().afterForkInParent(); },
                       [] { pool().afterForkInChild(); });
        return p;
    }();
    static const PoolShutdown shutdown;
    return *instance;
}

}  // namespace

void setPoolSpin(std::chrono::microseconds spin) noexcept {
    g_spinMicros.store(spin.count(), std::memory_order_relaxed);
}

void runOnPool(const ChunkTask& task) noexcept {
    auto job = std::make_shared<ChunkJob>(task);
    WorkerPool& workers = pool();
    const bool posted = workers.post(job, size_t(task.threads - 1));
    job->work(0);
    if (posted) workers.withdraw(job.get());
    job->waitAll();
}

size_t poolWorkerCount() noexcept { return pool().workerCount(); }

size_t poolIdleWorkerCount() noexcept { return pool().idleWorkerCount(); }

}  // namespace rthdist::core
