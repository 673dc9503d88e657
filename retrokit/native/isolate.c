/*
 * Giving each core copy its own rand(): libc's random-number state is one per
 * process, so two emulators calling rand() would change each other's games,
 * and race when they run in two threads.
 *
 * After a core copy is loaded, its relocations for rand, srand, random and
 * srandom are pointed at the functions below, which keep the state in the
 * emulator that the calling thread is running (rk_current). They reproduce
 * glibc's generator exactly (the additive feedback one behind random(),
 * seeded by default as srand(1) would), so a fresh emulator sees the same
 * numbers a fresh process with the real libc would.
 */
#define _GNU_SOURCE
#include "isolate.h"

#include <dlfcn.h>
#include <elf.h>
#include <link.h>
#include <pthread.h>
#include <stdint.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "callbacks.h"

/* ---- glibc's random(), state per emulator ------------------------------------------------------ */

void rk_rand_seed(rk_rand *r, unsigned seed) {
    int32_t word = seed == 0 ? 1 : (int32_t)seed;
    r->state[0] = word;
    for (int i = 1; i < RK_RAND_DEGREE; i++) {
        /* state[i] = 16807 * state[i - 1] % 2147483647, without overflow (Schrage). */
        int32_t hi = word / 127773, lo = word % 127773;
        word = 16807 * lo - 2836 * hi;
        if (word < 0) word += 2147483647;
        r->state[i] = word;
    }
    r->front = RK_RAND_SEP;
    r->rear = 0;
    for (int i = 0; i < 10 * RK_RAND_DEGREE; i++) rk_rand_next(r);
}

int32_t rk_rand_next(rk_rand *r) {
    uint32_t val = (uint32_t)r->state[r->front] + (uint32_t)r->state[r->rear];
    r->state[r->front] = (int32_t)val;
    int32_t result = (int32_t)((val >> 1) & 0x7fffffff);
    if (++r->front >= RK_RAND_DEGREE) {
        r->front = 0;
        ++r->rear;
    } else if (++r->rear >= RK_RAND_DEGREE) {
        r->rear = 0;
    }
    return result;
}

/* Calls from outside any emulator (a core's own thread) share one guarded state. */
static rk_rand outside;
static int outside_ready;
static pthread_mutex_t outside_lock = PTHREAD_MUTEX_INITIALIZER;

static int32_t shim_random(void) {
    rk_core *core = rk_current;
    if (core) return rk_rand_next(&core->rand);
    pthread_mutex_lock(&outside_lock);
    if (!outside_ready) rk_rand_seed(&outside, 1), outside_ready = 1;
    int32_t v = rk_rand_next(&outside);
    pthread_mutex_unlock(&outside_lock);
    return v;
}

static void shim_srandom(unsigned seed) {
    rk_core *core = rk_current;
    if (core) {
        rk_rand_seed(&core->rand, seed);
        return;
    }
    pthread_mutex_lock(&outside_lock);
    rk_rand_seed(&outside, seed);
    outside_ready = 1;
    pthread_mutex_unlock(&outside_lock);
}

static int shim_rand(void) { return shim_random(); }
static long shim_random_long(void) { return shim_random(); }
static void shim_srand(unsigned seed) { shim_srandom(seed); }

static const struct {
    const char *name;
    void *replacement;
} shims[] = {
    {"rand", (void *)shim_rand}, {"random", (void *)shim_random_long},
    {"srand", (void *)shim_srand}, {"srandom", (void *)shim_srand},
};

/* ---- pointing a loaded library's relocations at the shims -------------------------------------- */

static uintptr_t absolute(uintptr_t base, uintptr_t value) {
    /* glibc has usually relocated these dynamic entries already. */
    return value < base ? value + base : value;
}

static int patch_slot(void **slot, void *value, uintptr_t relro_start, uintptr_t relro_end) {
    long page = sysconf(_SC_PAGESIZE);
    uintptr_t start = (uintptr_t)slot & ~(uintptr_t)(page - 1);
    int in_relro = (uintptr_t)slot >= relro_start && (uintptr_t)slot < relro_end;
    if (in_relro && mprotect((void *)start, (size_t)page, PROT_READ | PROT_WRITE) != 0) return -1;
    *slot = value;
    if (in_relro) mprotect((void *)start, (size_t)page, PROT_READ);
    return 0;
}

int rk_isolate_core(rk_core *core) {
    struct link_map *map = NULL;
    if (dlinfo(core->handle, RTLD_DI_LINKMAP, &map) != 0 || !map) return -1;
    uintptr_t base = (uintptr_t)map->l_addr;
    const ElfW(Sym) *symtab = NULL;
    const char *strtab = NULL;
    const ElfW(Rela) *tables[2] = {NULL, NULL}; /* the PLT's relocations, then the others */
    size_t sizes[2] = {0, 0};
    for (const ElfW(Dyn) *d = map->l_ld; d->d_tag != DT_NULL; d++) {
        switch (d->d_tag) {
        case DT_SYMTAB: symtab = (const ElfW(Sym) *)absolute(base, d->d_un.d_ptr); break;
        case DT_STRTAB: strtab = (const char *)absolute(base, d->d_un.d_ptr); break;
        case DT_JMPREL: tables[0] = (const ElfW(Rela) *)absolute(base, d->d_un.d_ptr); break;
        case DT_PLTRELSZ: sizes[0] = d->d_un.d_val; break;
        case DT_RELA: tables[1] = (const ElfW(Rela) *)absolute(base, d->d_un.d_ptr); break;
        case DT_RELASZ: sizes[1] = d->d_un.d_val; break;
        }
    }
    if (!symtab || !strtab) return -1;
    /* Find the RELRO range: its pages are read-only after loading. */
    uintptr_t relro_start = 0, relro_end = 0;
    const ElfW(Ehdr) *ehdr = (const ElfW(Ehdr) *)base;
    if (memcmp(ehdr->e_ident, ELFMAG, SELFMAG) == 0) {
        const ElfW(Phdr) *ph = (const ElfW(Phdr) *)(base + ehdr->e_phoff);
        for (int i = 0; i < ehdr->e_phnum; i++) {
            if (ph[i].p_type == PT_GNU_RELRO) {
                /* As glibc does: only whole pages are made read-only. */
                uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE);
                relro_start = (base + ph[i].p_vaddr) & ~(page - 1);
                relro_end = (base + ph[i].p_vaddr + ph[i].p_memsz) & ~(page - 1);
            }
        }
    }
    int patched = 0;
    for (int t = 0; t < 2; t++) {
        for (size_t i = 0; tables[t] && i < sizes[t] / sizeof(ElfW(Rela)); i++) {
            const ElfW(Rela) *r = &tables[t][i];
            size_t sym = ELF64_R_SYM(r->r_info); /* 0: the relocation names no symbol */
            for (size_t k = 0; sym && k < sizeof shims / sizeof shims[0]; k++)
                if (strcmp(strtab + symtab[sym].st_name, shims[k].name) == 0 &&
                    patch_slot((void **)(base + r->r_offset), shims[k].replacement, relro_start, relro_end) == 0)
                    patched++;
        }
    }
    return patched;
}
