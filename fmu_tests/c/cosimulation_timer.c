/*
 * Times one build of the actuator FMU's shared library from a plain C importer, for
 * scripts/bench_vs_commit.sh, which runs two builds through it side by side.
 *
 * usage: cosimulation_timer [--repeat N] [--cold] [--csv FILE] LIBRARY GUID
 *        cosimulation_timer --pairs N LIBRARY_A GUID_A LIBRARY_B GUID_B
 *
 * It loads LIBRARY (a libjetpipe.so) and runs a 10 s co-simulation at 1 kHz: fmi2DoStep of
 * 1 ms, the inputs v_DA and x_s of the standard scenario (src/scenario.rs: sampled every
 * 10 ms and held, as fmu_tests/c/scenario_driver.c sets them), default parameters and
 * tolerance, F_act, P1, P2, i and x_jp read after every step. A run starts with
 * fmi2Instantiate and ends with fmi2FreeInstance. One untimed run warms the library (page
 * faults, first-use tables) before N timed ones (--repeat, default 1); --cold skips it, for an
 * instruction count of exactly one run under callgrind.
 *
 * Prints key=value lines: cpu_ms (the process's CPU time, CLOCK_PROCESS_CPUTIME_ID, of the
 * fastest timed run), wall_ms (its wall time), and digest (64-bit FNV-1a of the bits of the
 * five outputs at every step: two builds agree bit for bit if and only if, barring a
 * collision, their digests are equal). --csv FILE also writes t and the five outputs after
 * every step of the last run with 17 significant digits, for a comparison that says by how
 * much two builds differ.
 *
 * --pairs N loads two builds into the one process (each with RTLD_LOCAL, so each keeps its
 * own symbols and state), warms both, then times N pairs of runs, one of each build, the
 * order alternating from pair to pair: the two runs of a pair are some 20 ms apart, so a
 * change in the machine's speed (another tenant, the clock) falls on both. Prints
 * median_ratio (the median over the pairs of B's CPU time over A's), median_a_ms,
 * median_b_ms, min_a_ms, min_b_ms, and digest_a, digest_b.
 * Exit status 0 on success, 1 on any failure, 2 on bad usage.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2Functions.h"

static const fmi2ValueReference INPUTS[2] = {1u, 2u};                  /* v_DA, x_s */
static const fmi2ValueReference OUTPUTS[5] = {10u, 11u, 12u, 13u, 14u}; /* F_act, P1, P2, i, x_jp */

#define SAMPLE 0.01
#define SAMPLES 1000
#define STEP 1e-3
#define STEPS_PER_SAMPLE 10

/* The standard scenario, with the floating-point expressions of scenario_driver.c. */
static void inputs(int k, fmi2Real u[2]) {
    const double pi = 3.14159265358979323846;
    double t = SAMPLE * k;
    u[0] = 2.5 + 3.0 * sin(2.0 * pi * 0.3 * t) + 0.5 * sin(2.0 * pi * 6.0 * t);
    u[1] = 0.054 + 0.01 * sin(2.0 * pi * 0.1 * t);
}

static void logger(fmi2ComponentEnvironment env, fmi2String instanceName, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list args;
    (void)env;
    (void)category;
    if (status < fmi2Warning) return; /* only problems: printing would be part of the timing */
    fprintf(stderr, "[%d] %s: ", (int)status, instanceName ? instanceName : "");
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fprintf(stderr, "\n");
}

/* One loaded build: its exported functions and its GUID. */
typedef struct {
    const char *library, *guid;
    fmi2InstantiateTYPE *Instantiate;
    fmi2FreeInstanceTYPE *FreeInstance;
    fmi2SetupExperimentTYPE *SetupExperiment;
    fmi2EnterInitializationModeTYPE *EnterInitializationMode;
    fmi2ExitInitializationModeTYPE *ExitInitializationMode;
    fmi2TerminateTYPE *Terminate;
    fmi2SetRealTYPE *SetReal;
    fmi2GetRealTYPE *GetReal;
    fmi2DoStepTYPE *DoStep;
} Build;
static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

#define CHECK(call)                                                            \
    do {                                                                       \
        fmi2Status s_ = (call);                                                \
        if (s_ != fmi2OK) {                                                    \
            fprintf(stderr, "%s returned %d\n", #call, (int)s_);              \
            exit(1);                                                           \
        }                                                                      \
    } while (0)

static double seconds(clockid_t clock) {
    struct timespec ts;
    clock_gettime(clock, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static uint64_t fnv1a(uint64_t hash, double value) {
    uint64_t bits;
    memcpy(&bits, &value, sizeof bits);
    for (int i = 0; i < 8; i++) {
        hash ^= (bits >> (8 * i)) & 0xffu;
        hash *= 0x100000001b3ull;
    }
    return hash;
}

/* One run of the scenario; the digest of its outputs, and each step's outputs to `csv` if set. */
static uint64_t run(const Build *b, FILE *csv) {
    fmi2Component c = b->Instantiate("timer", fmi2CoSimulation, b->guid, "", &callbacks, fmi2False, fmi2False);
    fmi2Real u[2], y[5];
    uint64_t digest = 0xcbf29ce484222325ull;
    if (!c) {
        fprintf(stderr, "fmi2Instantiate returned NULL (is %s the GUID of %s?)\n", b->guid, b->library);
        exit(1);
    }
    inputs(0, u);
    CHECK(b->SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(b->EnterInitializationMode(c));
    CHECK(b->SetReal(c, INPUTS, 2, u));
    CHECK(b->ExitInitializationMode(c));
    for (int k = 0; k < SAMPLES; k++) {
        inputs(k, u);
        CHECK(b->SetReal(c, INPUTS, 2, u));
        for (int j = 0; j < STEPS_PER_SAMPLE; j++) {
            int n = k * STEPS_PER_SAMPLE + j;
            CHECK(b->DoStep(c, n * STEP, STEP, fmi2True));
            CHECK(b->GetReal(c, OUTPUTS, 5, y));
            for (int m = 0; m < 5; m++) digest = fnv1a(digest, y[m]);
            if (csv)
                fprintf(csv, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", (n + 1) * STEP, y[0], y[1], y[2],
                        y[3], y[4]);
        }
    }
    CHECK(b->Terminate(c));
    b->FreeInstance(c);
    return digest;
}

#define RESOLVE(name)                                                          \
    do {                                                                       \
        b->name = (fmi2##name##TYPE *)dlsym(lib, "fmi2" #name);                \
        if (!b->name) {                                                        \
            fprintf(stderr, "%s: cannot resolve fmi2%s\n", library, #name);     \
            return 1;                                                          \
        }                                                                      \
    } while (0)

/* Loads `library` into `b`; 0 on success. */
static int load(Build *b, const char *library, const char *guid) {
    void *lib = dlopen(library, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "cannot load %s: %s\n", library, dlerror());
        return 1;
    }
    b->library = library;
    b->guid = guid;
    RESOLVE(Instantiate);
    RESOLVE(FreeInstance);
    RESOLVE(SetupExperiment);
    RESOLVE(EnterInitializationMode);
    RESOLVE(ExitInitializationMode);
    RESOLVE(Terminate);
    RESOLVE(SetReal);
    RESOLVE(GetReal);
    RESOLVE(DoStep);
    return 0;
}

/* The CPU seconds of one run of `b`, its digest in *digest. */
static double timed_run(const Build *b, uint64_t *digest) {
    double cpu0 = seconds(CLOCK_PROCESS_CPUTIME_ID);
    *digest = run(b, NULL);
    return seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu0;
}

static int compare_doubles(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

static double median(double *v, int n) {
    qsort(v, (size_t)n, sizeof *v, compare_doubles);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* --pairs: the two builds interleaved in one process (see the header). */
static int pairs_mode(int pairs, Build *a, Build *b) {
    double *ta = malloc(sizeof(double) * (size_t)pairs), *tb = malloc(sizeof(double) * (size_t)pairs);
    double *ratio = malloc(sizeof(double) * (size_t)pairs);
    uint64_t digest_a, digest_b, first_a = run(a, NULL), first_b = run(b, NULL);
    double min_a = INFINITY, min_b = INFINITY;
    if (!ta || !tb || !ratio) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    for (int k = 0; k < pairs; k++) {
        if (k % 2 == 0) {
            ta[k] = timed_run(a, &digest_a);
            tb[k] = timed_run(b, &digest_b);
        } else {
            tb[k] = timed_run(b, &digest_b);
            ta[k] = timed_run(a, &digest_a);
        }
        if (digest_a != first_a || digest_b != first_b) {
            fprintf(stderr, "two runs of the same build differ\n");
            return 1;
        }
        ratio[k] = tb[k] / ta[k];
        if (ta[k] < min_a) min_a = ta[k];
        if (tb[k] < min_b) min_b = tb[k];
    }
    printf("median_ratio=%.4f\nmedian_a_ms=%.4f\nmedian_b_ms=%.4f\nmin_a_ms=%.4f\nmin_b_ms=%.4f\n",
           median(ratio, pairs), 1e3 * median(ta, pairs), 1e3 * median(tb, pairs), 1e3 * min_a, 1e3 * min_b);
    printf("digest_a=%016llx\ndigest_b=%016llx\n", (unsigned long long)first_a, (unsigned long long)first_b);
    free(ta);
    free(tb);
    free(ratio);
    return 0;
}

static int usage(const char *program) {
    fprintf(stderr, "usage: %s [--repeat N] [--cold] [--csv FILE] LIBRARY GUID\n", program);
    fprintf(stderr, "       %s --pairs N LIBRARY_A GUID_A LIBRARY_B GUID_B\n", program);
    return 2;
}

/* The count after `option` in 1..=max into *count; 0 on success, else a message and 2. */
static int parse_count(const char *option, const char *text, long max, int *count) {
    char *end;
    long n = strtol(text, &end, 10);
    if (*end != '\0' || n < 1 || n > max) {
        fprintf(stderr, "%s %s: expected an integer from 1 to %ld\n", option, text, max);
        return 2;
    }
    *count = (int)n;
    return 0;
}

int main(int argc, char **argv) {
    int repeat = 1, cold = 0, arg = 1, pairs = 0;
    const char *csv_path = NULL;
    while (arg < argc && strncmp(argv[arg], "--", 2) == 0) {
        if (strcmp(argv[arg], "--cold") == 0) {
            cold = 1;
            arg += 1;
        } else if (strcmp(argv[arg], "--repeat") == 0 && arg + 1 < argc) {
            if (parse_count("--repeat", argv[arg + 1], 1000, &repeat)) return 2;
            arg += 2;
        } else if (strcmp(argv[arg], "--pairs") == 0 && arg + 1 < argc) {
            if (parse_count("--pairs", argv[arg + 1], 100000, &pairs)) return 2;
            arg += 2;
        } else if (strcmp(argv[arg], "--csv") == 0 && arg + 1 < argc) {
            csv_path = argv[arg + 1];
            arg += 2;
        } else {
            return usage(argv[0]);
        }
    }
    if (pairs) {
        static Build a, b;
        if (argc - arg != 4 || cold || csv_path) return usage(argv[0]);
        if (load(&a, argv[arg], argv[arg + 1]) || load(&b, argv[arg + 2], argv[arg + 3])) return 1;
        return pairs_mode(pairs, &a, &b);
    }
    if (argc - arg != 2) return usage(argv[0]);
    static Build build;
    if (load(&build, argv[arg], argv[arg + 1])) return 1;

    FILE *csv = NULL;
    if (csv_path) {
        csv = fopen(csv_path, "w");
        if (!csv) {
            fprintf(stderr, "cannot write %s\n", csv_path);
            return 1;
        }
        fprintf(csv, "t,F_act,P1,P2,i,x_jp\n");
    }
    uint64_t first = cold ? 0 : run(&build, NULL), digest = 0;
    double best_cpu = INFINITY, best_wall = INFINITY;
    for (int r = 0; r < repeat; r++) {
        double cpu0 = seconds(CLOCK_PROCESS_CPUTIME_ID), wall0 = seconds(CLOCK_MONOTONIC);
        digest = run(&build, r == repeat - 1 ? csv : NULL);
        double cpu = seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu0, wall = seconds(CLOCK_MONOTONIC) - wall0;
        if (cpu < best_cpu) {
            best_cpu = cpu;
            best_wall = wall;
        }
        if (!cold && digest != first) {
            fprintf(stderr, "two runs of the same scenario differ: digests %016llx and %016llx\n",
                    (unsigned long long)first, (unsigned long long)digest);
            return 1;
        }
    }
    if (csv) fclose(csv);
    printf("cpu_ms=%.4f\nwall_ms=%.4f\ndigest=%016llx\n", 1e3 * best_cpu, 1e3 * best_wall,
           (unsigned long long)digest);
    return 0;
}
