#ifndef RETROKIT_RUNNER_H
#define RETROKIT_RUNNER_H

#include <pthread.h>
#include <semaphore.h>
#include <stdatomic.h>
#include <stdint.h>

#include "core.h"
#include "video.h"

/* One emulator's share of a batched step. */
typedef struct {
    rk_core *core;
    const uint16_t *actions; /* one mask per port */
    int frames;
    uint8_t *screen;         /* where to put the RGB frame, or NULL */
    unsigned screen_width, screen_height;
    int converted;           /* set: whether the frame fitted and was converted */
} rk_task;

typedef struct {
    pthread_t thread;
    sem_t wake;            /* posted only when the worker said it sleeps */
    rk_task *task;
    atomic_uint start;     /* bumped by the caller: a new task */
    atomic_uint done;      /* set to start by the worker: finished */
    atomic_int sleeping;
    atomic_int quit;
} rk_worker;

typedef struct {
    rk_worker *workers;
    int n_workers;
} rk_runner;

/* Start `threads` workers; 0 on success. */
int rk_runner_init(rk_runner *r, int threads);
/* Run n tasks (n - 1 <= workers) and wait for all; call without the GIL. */
void rk_runner_run(rk_runner *r, rk_task *tasks, int n);
/* Stop and join the workers. */
void rk_runner_close(rk_runner *r);

#endif
