#ifndef RETROKIT_RUNNER_H
#define RETROKIT_RUNNER_H

#include <pthread.h>
#include <semaphore.h>
#include <stdatomic.h>
#include <stdint.h>

#include "core.h"

/* One emulator's share of a batched step. */
typedef struct {
    rk_core *core;
    const uint16_t *actions; /* one mask per port */
    int frames;
    uint8_t *screen;         /* where to put the RGB frame, or NULL */
    unsigned screen_width, screen_height;
    int converted;           /* set: whether the frame fitted and was converted */
} rk_task;

struct rk_runner;

typedef struct {
    pthread_t thread;
    sem_t wake;            /* posted only when the worker said it sleeps */
    struct rk_runner *runner;
    atomic_uint start;     /* bumped by the caller: a call has tasks to share */
    atomic_uint done;      /* set to start by the worker: it takes no more of them */
    atomic_int sleeping;
    atomic_int quit;
} rk_worker;

typedef struct rk_runner {
    rk_worker *workers;
    int n_workers;
    rk_task *tasks;        /* the current call's tasks */
    int n_tasks;
    atomic_int next;       /* the next task nobody has taken */
} rk_runner;

/* Start `threads` workers; 0 on success. */
int rk_runner_init(rk_runner *r, int threads);
/* Run n tasks, any number, shared among the calling thread and the workers;
 * wait for all. Call without the GIL. */
void rk_runner_run(rk_runner *r, rk_task *tasks, int n);
/* Stop and join the workers. */
void rk_runner_close(rk_runner *r);

#endif
