/*
 * Running several emulators' frames at once on a pool of native threads.
 *
 * A vector env's step is one call: the GIL is released once, and the calling
 * thread and the workers take the emulators' tasks one at a time until none
 * is left, each converting its screen straight into the caller's batch.
 * There are no more threads than the caller asked for (a vector env asks for
 * one per CPU), so a vector of more envs than CPUs shares them instead of
 * crowding them.
 *
 * Nobody waits for a thread that has not started a task. A learner shares
 * the machine with its envs, so a worker is often descheduled when a call
 * begins; the tasks it has not taken are run by whoever is free (the caller
 * included), and the caller waits only for tasks actually in progress, by
 * counting finished tasks, not workers. A task is taken by one
 * compare-and-swap on a word holding both the call's number and the count of
 * tasks left, so a worker that wakes after its call ended finds the number
 * changed and takes nothing, and the caller may return as soon as the count
 * of finished tasks is complete.
 *
 * Between calls a worker spins a while (up to a millisecond) before it
 * sleeps: a step's Python part is short, and waking a sleeping thread (on a
 * virtual machine, a halted vCPU) costs more than the step gains. But only
 * while spinning is cheap: a worker that finds it lost the CPU while it spun
 * (a gap in its clock) knows the machine is oversubscribed (a learner, other
 * processes), and for the next calls it sleeps at once, since there a
 * spinning thread only takes a core from the others and, having used up its
 * share, is woken late, while a sleeping one is woken first. The caller posts
 * a worker's semaphore only if the worker says it sleeps; both sides write
 * their word before reading the other's, so no wake-up is lost. A caller
 * that waits for tasks in progress does the same: it spins while that is
 * cheap, then sleeps until the worker that finishes the last task wakes it.
 *
 * A waiting caller also moves a stalled worker onto its own CPU. Workers are
 * kept off the caller's CPU (see keep_workers_off_caller), so under load a
 * worker shares the other CPU with the busy process, and the scheduler, being
 * fair, may take that CPU from it in the middle of a task for a whole tick
 * (4 ms at 250 Hz, four steps' worth) while the caller's CPU sits idle,
 * since the caller has nothing left but to wait. So while it waits, the
 * caller reads each working worker's CPU-time clock every RK_WATCH_NS; one
 * that ran less than half the time for RK_STALL_NS is waiting for its CPU,
 * and the caller pins it to the caller's own CPU and sleeps there, which
 * hands that CPU to the worker at once. The next call lets it go back.
 */
#define _GNU_SOURCE /* clock_gettime under -std=c11; sched_getcpu and thread affinity */
#include "runner.h"

#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define RK_SPIN_NS 1000000     /* how long a waiting thread spins before it sleeps, on a quiet machine */
#define RK_PREEMPTED_NS 200000 /* a gap this long in a spinning thread's clock: it lost the CPU */
#define RK_BUSY_CALLS 256      /* calls for which a thread that lost the CPU while spinning sleeps at once */
#define RK_WATCH_NS 100000     /* how often a waiting caller reads its working workers' CPU-time clocks */
#define RK_STALL_NS 200000     /* a worker that ran under half of this long a stretch is waiting for its CPU */

static inline void cpu_relax(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ volatile("yield");
#endif
}

static inline uint32_t call_of(uint64_t work) { return (uint32_t)(work >> 32); }

/* Clock `clock` in nanoseconds into *ns; 0 on success. */
static inline int clock_ns(clockid_t clock, uint64_t *ns) {
    struct timespec t;
    if (clock_gettime(clock, &t) != 0) return -1;
    *ns = (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
    return 0;
}

static inline uint64_t now_ns(void) {
    uint64_t ns = 0;
    clock_ns(CLOCK_MONOTONIC, &ns);
    return ns;
}

/* Take and run the tasks of call `call` until none is left; tasks go from the last to the first.
 * `w` is the worker taking them, or NULL for the caller. */
static void take_tasks(rk_runner *r, uint32_t call, rk_worker *w) {
    uint64_t work = atomic_load(&r->work);
    while (call_of(work) == call && (uint32_t)work > 0) {
        if (!atomic_compare_exchange_weak(&r->work, &work, work - 1)) continue; /* `work` now holds the new word */
        rk_task *task = &r->tasks[(uint32_t)work - 1]; /* the call cannot end while one of its tasks runs */
        int n = r->n_tasks;                            /* (so this is still the call's) */
        if (w) atomic_store(&w->working, 1);
        rk_core_run(task->core, task->actions, task->core->n_ports, task->frames, task->after);
        task->converted =
            task->screen && rk_core_screen_into(task->core, task->screen, task->screen_width, task->screen_height);
        if (w) atomic_store(&w->working, 0);
        /* The last task done wakes a caller that sleeps; a post that comes late is a spurious wake-up the
         * caller's loop absorbs. */
        if (atomic_fetch_add(&r->finished, 1) + 1 == n && atomic_load(&r->caller_sleeping)) sem_post(&r->done);
        work = atomic_load(&r->work);
    }
}

/* Whether a thread waiting since `start` should still spin: up to RK_SPIN_NS, unless the machine is busy
 * (the thread lost the CPU lately, `*busy_calls`, or now: a gap in its clock since `*last`). */
static int keep_spinning(int *busy_calls, uint64_t start, uint64_t *last) {
    uint64_t t = now_ns();
    if (t - *last > RK_PREEMPTED_NS) *busy_calls = RK_BUSY_CALLS;
    *last = t;
    return *busy_calls == 0 && t - start < RK_SPIN_NS;
}

static void *worker_main(void *arg) {
    rk_worker *w = arg;
    rk_runner *r = w->runner;
    uint32_t seen = call_of(atomic_load(&r->work));
    for (;;) {
        uint64_t start = now_ns(), last = start, work;
        unsigned turn = 0;
        while (call_of(work = atomic_load(&r->work)) == seen && !atomic_load(&r->quit)) {
            cpu_relax();
            if (++turn % 64 || keep_spinning(&w->busy_calls, start, &last)) continue; /* clock: every 64 */
            atomic_store(&w->sleeping, 1);
            if (call_of(atomic_load(&r->work)) == seen && !atomic_load(&r->quit)) sem_wait(&w->wake);
            atomic_store(&w->sleeping, 0);
            start = last = now_ns();
        }
        if (atomic_load(&r->quit)) return NULL;
        seen = call_of(work);
        if (w->busy_calls > 0) w->busy_calls--;
        take_tasks(r, seen, w);
        /* Moved onto the caller's CPU, it must not spin there while the caller wakes: the machine is busy. */
        if (atomic_exchange(&w->moved, 0)) w->busy_calls = RK_BUSY_CALLS;
    }
}

/* Keep the workers off the CPU the caller runs on now. When a worker sleeps and the caller wakes it, Linux
 * places it beside its waker if no CPU is idle, which under load (another process on the other core) puts
 * both of our threads on the caller's core while that process keeps the other core to itself: the two
 * emulators then run one after the other, plus the cost of switching. Kept off the caller's CPU, a worker
 * shares the busy core instead, where, sleeping between tasks, it is run ahead of a process that never
 * sleeps. Only done when the caller's CPU changed (a syscall per worker), and never when the process may
 * use only the caller's CPU. */
static void keep_workers_off_caller(rk_runner *r) {
    if (!r->cpus) return;
    int cpu = sched_getcpu();
    if (cpu < 0 || cpu == r->caller_cpu) return;
    r->caller_cpu = cpu;
    cpu_set_t set;
    memcpy(&set, r->cpus, sizeof set);
    if (CPU_ISSET(cpu, &set) && CPU_COUNT(&set) > 1) CPU_CLR(cpu, &set);
    for (int i = 0; i < r->n_workers; i++) pthread_setaffinity_np(r->workers[i].thread, sizeof set, &set);
}

/* Whether worker `w`, working, has been waiting for its CPU: it ran under half of the last RK_STALL_NS or more
 * (since the caller began to watch it, or since it last ran over half of a stretch). */
static int stalled(rk_worker *w, uint64_t now) {
    uint64_t ran;
    if (!w->has_clock || clock_ns(w->clock, &ran) != 0) return 0;
    if (!w->watch_at) {
        w->watch_cpu = ran, w->watch_at = now;
        return 0;
    }
    uint64_t wall = now - w->watch_at;
    if (wall < RK_STALL_NS) return 0;
    if ((ran - w->watch_cpu) * 2 < wall) return 1;
    w->watch_cpu = ran, w->watch_at = now; /* it ran: watch a new stretch */
    return 0;
}

/* Called by a waiting caller at most every RK_WATCH_NS: pin the first stalled worker to the caller's CPU and
 * return 1 (the caller then sleeps, handing its CPU over); else 0. */
static int move_stalled_worker(rk_runner *r) {
    uint64_t now = now_ns();
    if (!r->cpus || now - r->watched_at < RK_WATCH_NS) return 0;
    r->watched_at = now;
    for (int i = 0; i < r->n_workers; i++) {
        rk_worker *w = &r->workers[i];
        if (!atomic_load(&w->working)) {
            w->watch_at = 0;
            continue;
        }
        if (!stalled(w, now)) continue;
        int cpu = sched_getcpu();
        if (cpu < 0 || !CPU_ISSET(cpu, (cpu_set_t *)r->cpus)) return 0;
        cpu_set_t here;
        CPU_ZERO(&here);
        CPU_SET(cpu, &here);
        atomic_store(&w->moved, 1);
        if (pthread_setaffinity_np(w->thread, sizeof here, &here) != 0) return 0;
        r->caller_cpu = -1; /* so the next call lets it go back off the caller's CPU */
        r->moved++;
        return 1;
    }
    return 0;
}

/* Wait until all n tasks of the call are done: spin while it is cheap, then sleep until the worker that
 * finishes the last one wakes the caller; meanwhile, watch for a stalled worker to move onto this CPU. */
static void wait_for_tasks(rk_runner *r, int n) {
    for (int i = 0; i < r->n_workers; i++) r->workers[i].watch_at = 0;
    r->watched_at = 0;
    int moved = 0;
    uint64_t start = now_ns(), last = start;
    for (unsigned turn = 1; atomic_load(&r->finished) != n; turn++) {
        cpu_relax();
        if (turn % 64) continue;
        if (!moved) moved = move_stalled_worker(r);
        if (!moved && keep_spinning(&r->busy_calls, start, &last)) continue;
        atomic_store(&r->caller_sleeping, 1);
        while (atomic_load(&r->finished) != n) {
            if (moved || !r->cpus) {
                sem_wait(&r->done);
                continue;
            }
            /* sem_timedwait's realtime clock, not sem_clockwait's monotonic one (glibc 2.30+): a jump of the
             * clock only ends one wait early or late, and the loop looks again. */
            struct timespec t;
            clock_gettime(CLOCK_REALTIME, &t);
            t.tv_nsec += RK_WATCH_NS;
            if (t.tv_nsec >= 1000000000) t.tv_sec++, t.tv_nsec -= 1000000000;
            sem_timedwait(&r->done, &t);
            moved = move_stalled_worker(r);
        }
        atomic_store(&r->caller_sleeping, 0);
    }
}

int rk_runner_init(rk_runner *r, int threads) {
    memset(r, 0, sizeof *r);
    r->caller_cpu = -1;
    cpu_set_t *cpus = malloc(sizeof *cpus);
    if (cpus && sched_getaffinity(0, sizeof *cpus, cpus) == 0 && CPU_COUNT(cpus) > 1) r->cpus = cpus;
    else free(cpus);
    r->workers = calloc((size_t)(threads > 0 ? threads : 1), sizeof(rk_worker));
    if (!r->workers) return -1;
    sem_init(&r->done, 0, 0);
    for (int i = 0; i < threads; i++) {
        rk_worker *w = &r->workers[i];
        w->runner = r;
        sem_init(&w->wake, 0, 0);
        if (pthread_create(&w->thread, NULL, worker_main, w) != 0) {
            sem_destroy(&w->wake);
            rk_runner_close(r);
            return -1;
        }
        w->has_clock = pthread_getcpuclockid(w->thread, &w->clock) == 0;
        r->n_workers++;
    }
    return 0;
}

void rk_runner_run(rk_runner *r, rk_task *tasks, int n) {
    if (n <= 0) return;
    /* Every task of the last call finished, so no thread reads these until the new word is published. */
    r->tasks = tasks;
    r->n_tasks = n;
    atomic_store(&r->finished, 0);
    uint32_t call = call_of(atomic_load(&r->work)) + 1;
    atomic_store(&r->work, ((uint64_t)call << 32) | (uint32_t)n);
    int helpers = n - 1 < r->n_workers ? n - 1 : r->n_workers;
    if (helpers > 0) keep_workers_off_caller(r);
    for (int i = 0; i < helpers; i++) {
        rk_worker *w = &r->workers[i];
        if (atomic_load(&w->sleeping)) sem_post(&w->wake);
    }
    take_tasks(r, call, NULL);
    /* Only tasks that some worker took and is still running are left to wait for. */
    wait_for_tasks(r, n);
    if (r->busy_calls > 0) r->busy_calls--;
}

void rk_runner_close(rk_runner *r) {
    atomic_store(&r->quit, 1);
    for (int i = 0; i < r->n_workers; i++) sem_post(&r->workers[i].wake);
    for (int i = 0; i < r->n_workers; i++) {
        pthread_join(r->workers[i].thread, NULL);
        sem_destroy(&r->workers[i].wake);
    }
    free(r->workers);
    r->workers = NULL;
    free(r->cpus);
    r->cpus = NULL;
    r->n_workers = 0;
    sem_destroy(&r->done);
}
