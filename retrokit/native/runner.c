/*
 * Running several emulators' frames at once on a pool of native threads.
 *
 * A vector env's step is one call: the GIL is released once, and the calling
 * thread and the workers take the emulators' tasks one at a time from a
 * shared counter until none is left, each converting its screen straight into
 * the caller's batch. There are no more threads than the caller asked for
 * (a vector env asks for one per CPU), so a vector of more envs than CPUs
 * shares them instead of crowding them, and a thread held up by the machine
 * leaves its share to the others.
 *
 * Between calls a worker spins for a while before it sleeps: a step's Python
 * part is short, and waking a sleeping thread (on a virtual machine, a halted
 * vCPU) costs more than the step gains. The caller announces a call by
 * bumping `start` and posts the semaphore only if the worker says it sleeps;
 * both sides write their flag before reading the other's, so no wake-up is
 * lost. The caller returns only once every worker it woke has said it takes
 * no more tasks, so none touches them after.
 */
#include "runner.h"

#include <sched.h>
#include <stdlib.h>
#include <string.h>

#define RK_SPINS 100000 /* about a millisecond of pause instructions */

static inline void cpu_relax(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ volatile("yield");
#endif
}

static void do_task(rk_task *task) {
    rk_core_run(task->core, task->actions, task->core->n_ports, task->frames);
    task->converted = task->screen && rk_core_screen_into(task->core, task->screen, task->screen_width,
                                                          task->screen_height);
}

static void take_tasks(rk_runner *r) {
    for (int i; (i = atomic_fetch_add(&r->next, 1)) < r->n_tasks;) do_task(&r->tasks[i]);
}

static void *worker_main(void *arg) {
    rk_worker *w = arg;
    unsigned seen = 0;
    for (;;) {
        int spins = 0;
        while (atomic_load(&w->start) == seen && !atomic_load(&w->quit)) {
            if (++spins < RK_SPINS) {
                cpu_relax();
                continue;
            }
            atomic_store(&w->sleeping, 1);
            if (atomic_load(&w->start) == seen && !atomic_load(&w->quit)) sem_wait(&w->wake);
            atomic_store(&w->sleeping, 0);
            spins = 0;
        }
        if (atomic_load(&w->quit)) return NULL;
        seen = atomic_load(&w->start);
        take_tasks(w->runner);
        atomic_store(&w->done, seen);
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
    r->tasks = tasks;
    r->n_tasks = n;
    atomic_store(&r->next, 0);
    int helpers = n - 1 < r->n_workers ? n - 1 : r->n_workers;
    for (int i = 0; i < helpers; i++) {
        rk_worker *w = &r->workers[i];
        atomic_fetch_add(&w->start, 1);
        if (atomic_load(&w->sleeping)) sem_post(&w->wake);
    }
    take_tasks(r);
    for (int i = 0; i < helpers; i++) {
        rk_worker *w = &r->workers[i];
        unsigned target = atomic_load(&w->start);
        for (int spins = 0; atomic_load(&w->done) != target; spins++) {
            if (spins < RK_SPINS) cpu_relax();
            else sched_yield();
        }
    }
}

void rk_runner_close(rk_runner *r) {
    for (int i = 0; i < r->n_workers; i++) {
        atomic_store(&r->workers[i].quit, 1);
        sem_post(&r->workers[i].wake);
    }
    for (int i = 0; i < r->n_workers; i++) {
        pthread_join(r->workers[i].thread, NULL);
        sem_destroy(&r->workers[i].wake);
    }
    free(r->workers);
    r->workers = NULL;
    r->n_workers = 0;
}
