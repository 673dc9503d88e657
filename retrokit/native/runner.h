#ifndef RETROKIT_RUNNER_H
#define RETROKIT_RUNNER_H

#include <pthread.h>
#include <semaphore.h>
#include <time.h>
#include <stdatomic.h>
#include <stdint.h>

#include "core.h"

/* One emulator's share of a batched step. */
typedef struct {
    rk_core *core;
    const uint16_t *actions; /* one mask per port */
    int frames, after;       /* frames to run, and frames of the step after them (rk_core_run) */
    uint8_t *screen;         /* where to put the RGB frame, or NULL */
    unsigned screen_width, screen_height;
    int converted;           /* set: whether the frame fitted and was converted */
} rk_task;

struct rk_runner;

typedef struct {
    pthread_t thread;
    sem_t wake;            /* posted only when the worker said it sleeps */
    struct rk_runner *runner;
    atomic_int sleeping;
    atomic_int working;    /* set while it runs a task */
    atomic_int moved;      /* set by a caller that moved it onto its CPU (the machine is busy) */
    int busy_calls;        /* calls left for which this worker sleeps at once: it lost the CPU while spinning */
    /* Read by a waiting caller only: the worker's CPU-time clock, and when the caller last read it. */
    clockid_t clock;
    int has_clock;
    uint64_t watch_cpu, watch_at;
} rk_worker;

/* The most tasks one call may have: a call's tasks left are counted in the low 32 bits of `work`. */
#define RK_MAX_TASKS 0x7fffffff

typedef struct rk_runner {
    rk_worker *workers;
    int n_workers;
    rk_task *tasks;        /* the current call's tasks */
    int n_tasks;
    /* The call's number (high 32 bits) and how many of its tasks nobody took yet (low 32 bits), in one word:
     * a task is taken by one compare-and-swap that also checks the call, so a thread that wakes late can
     * never take a task of a call other than the one it saw. */
    _Atomic uint64_t work;
    atomic_int finished;   /* tasks of the current call done */
    sem_t done;            /* posted by the worker that finishes a call's last task, if the caller sleeps */
    atomic_int caller_sleeping;
    int busy_calls;        /* calls left for which the caller sleeps at once: it lost the CPU while spinning */
    void *cpus;            /* the CPUs the process may use (a cpu_set_t), or NULL: workers are kept off the caller's */
    int caller_cpu;        /* the CPU the workers were last kept off, or -1 */
    uint64_t watched_at;   /* when a waiting caller last read the workers' clocks */
    uint64_t moved;        /* how many times a waiting caller moved a stalled worker onto its own CPU */
    atomic_int quit;
} rk_runner;

/* Start `threads` workers; 0 on success. */
int rk_runner_init(rk_runner *r, int threads);
/* Run n tasks (at most RK_MAX_TASKS), shared among the calling thread and whichever workers are free;
 * return once all are done. Call without the GIL. */
void rk_runner_run(rk_runner *r, rk_task *tasks, int n);
/* Stop and join the workers. */
void rk_runner_close(rk_runner *r);

#endif
