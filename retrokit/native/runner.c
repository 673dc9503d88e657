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
 * Between calls a worker waits a little before it sleeps: a step's Python
 * part is short, and waking a sleeping thread (on a virtual machine, a halted
 * vCPU) costs more than the step gains. It waits by yielding the CPU, not by
 * spinning on it, so that on a busy machine the waiting costs the caller's
 * thread (or a learner) nothing. The caller posts a worker's semaphore only
 * if the worker says it sleeps; both sides write their word before reading
 * the other's, so no wake-up is lost.
 */
#include "runner.h"

#include <sched.h>
#include <stdlib.h>
#include <string.h>

#define RK_PAUSES 200  /* a few microseconds of pause instructions before the first yield */
#define RK_YIELDS 2000 /* about a millisecond of yields on an idle machine before a worker sleeps */

static inline void cpu_relax(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ volatile("yield");
#endif
}

/* One more turn of waiting: pause first, then give the CPU to whoever else wants it. */
static inline void wait_turn(int turn) {
    if (turn < RK_PAUSES) cpu_relax();
    else sched_yield();
}

static inline uint32_t call_of(uint64_t work) { return (uint32_t)(work >> 32); }

/* Take and run the tasks of call `call` until none is left; tasks go from the last to the first. */
static void take_tasks(rk_runner *r, uint32_t call) {
    uint64_t work = atomic_load(&r->work);
    while (call_of(work) == call && (uint32_t)work > 0) {
        if (!atomic_compare_exchange_weak(&r->work, &work, work - 1)) continue; /* `work` now holds the new word */
        rk_task *task = &r->tasks[(uint32_t)work - 1]; /* the call cannot end while one of its tasks runs */
        rk_core_run(task->core, task->actions, task->core->n_ports, task->frames);
        task->converted =
            task->screen && rk_core_screen_into(task->core, task->screen, task->screen_width, task->screen_height);
        atomic_fetch_add(&r->finished, 1);
        work = atomic_load(&r->work);
    }
}

static void *worker_main(void *arg) {
    rk_worker *w = arg;
    rk_runner *r = w->runner;
    uint32_t seen = call_of(atomic_load(&r->work));
    for (;;) {
        int turn = 0;
        uint64_t work;
        while (call_of(work = atomic_load(&r->work)) == seen && !atomic_load(&r->quit)) {
            if (++turn < RK_PAUSES + RK_YIELDS) {
                wait_turn(turn);
                continue;
            }
            atomic_store(&w->sleeping, 1);
            if (call_of(atomic_load(&r->work)) == seen && !atomic_load(&r->quit)) sem_wait(&w->wake);
            atomic_store(&w->sleeping, 0);
            turn = 0;
        }
        if (atomic_load(&r->quit)) return NULL;
        seen = call_of(work);
        take_tasks(r, seen);
    }
}

int rk_runner_init(rk_runner *r, int threads) {
    memset(r, 0, sizeof *r);
    r->workers = calloc((size_t)(threads > 0 ? threads : 1), sizeof(rk_worker));
    if (!r->workers) return -1;
    for (int i = 0; i < threads; i++) {
        rk_worker *w = &r->workers[i];
        w->runner = r;
        sem_init(&w->wake, 0, 0);
        if (pthread_create(&w->thread, NULL, worker_main, w) != 0) {
            sem_destroy(&w->wake);
            rk_runner_close(r);
            return -1;
        }
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
    for (int i = 0; i < helpers; i++) {
        rk_worker *w = &r->workers[i];
        if (atomic_load(&w->sleeping)) sem_post(&w->wake);
    }
    take_tasks(r, call);
    /* Only tasks that some worker took and is still running are left to wait for. */
    for (int turn = 0; atomic_load(&r->finished) != n; turn++) wait_turn(turn);
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
    r->n_workers = 0;
}
