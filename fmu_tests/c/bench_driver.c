/*
 * Benchmark driver of the JetPipeActuator FMU in plain C (fmu_tests/bench_fmu.py compiles and
 * runs it): the model's own cost, with no importer overhead, and its memory per instance.
 *
 * usage: bench_driver EXTRACTED_FMU_DIR GUID MODE N
 *
 *   standard    N instances stepped in lockstep through the standard scenario (10 s, inputs
 *               sampled every 10 ms and held, one p_DoStep per sample, as
 *               fmu_tests/scenarios.py's step_scenario does it)
 *   closedloop  N instances in lockstep under the 500 Hz proportional force loop of
 *               bench_fmu.py (2 ms steps, 10 s; see closed_loop_* below)
 *   memory      N instances alive at once: instantiate, setup, initialise, one 10 ms step
 *               each; VmRSS/VmHWM before and after; then free them all
 *
 * Prints key=value lines. CPU time is the process's (CLOCK_PROCESS_CPUTIME_ID); the library
 * is loaded and one instance run before any clock starts, so page faults of loading and
 * first-use initialisation are not counted.
 * Exit status 0 on success, 1 on any failure.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2Functions.h"

/* Python's math.pi (M_PI is not in C99). */
#define PI 3.141592653589793

#define VR_V_DA 1u
#define VR_X_S 2u
#define VR_F_ACT 10u
#define VR_P1 11u
#define VR_P2 12u

/* The standard scenario (src/scenario.rs, fmu_tests/scenarios.py), with the same floating-
 * point expressions so the results are bitwise those of the Python loop. */
#define SAMPLE 0.01
#define N_SAMPLES 1000
static double v_da_sample(int k) {
    double t = SAMPLE * k;
    return 2.5 + 3.0 * sin(2 * PI * 0.3 * t) + 0.5 * sin(2 * PI * 6 * t);
}
static double x_s_sample(int k) {
    double t = SAMPLE * k;
    return 0.054 + 0.01 * sin(2 * PI * 0.1 * t);
}

/* The closed-loop scenario (bench_fmu.py documents it): 500 Hz, 10 s, x_s = 0.054 m,
 * v_DA = V_FF + KP (F_ref - F_act), clamped to +-10 V, F_ref a staircase then a sine. */
#define CL_STEP 0.002
#define CL_STEPS 5000
#define CL_V_FF 2.5
#define CL_KP 0.1
static double closed_loop_reference(double t) {
    if (t < 2.0) return 20.0;
    if (t < 4.0) return 60.0;
    if (t < 6.0) return 35.0;
    return 40.0 + 20.0 * sin(2 * PI * 0.5 * (t - 6.0));
}
static double closed_loop_command(double t, double force) {
    double v = CL_V_FF + CL_KP * (closed_loop_reference(t) - force);
    return v > 10.0 ? 10.0 : (v < -10.0 ? -10.0 : v);
}

static void logger(fmi2ComponentEnvironment env, fmi2String instanceName, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list args;
    (void)env;
    if (status < fmi2Warning) return; /* only problems: printing would be part of the timing */
    fprintf(stderr, "[%d] [%s] %s: ", (int)status, category ? category : "", instanceName ? instanceName : "");
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fprintf(stderr, "\n");
}

static fmi2InstantiateTYPE *p_Instantiate;
static fmi2FreeInstanceTYPE *p_FreeInstance;
static fmi2SetupExperimentTYPE *p_SetupExperiment;
static fmi2EnterInitializationModeTYPE *p_EnterInitializationMode;
static fmi2ExitInitializationModeTYPE *p_ExitInitializationMode;
static fmi2TerminateTYPE *p_Terminate;
static fmi2SetRealTYPE *p_SetReal;
static fmi2GetRealTYPE *p_GetReal;
static fmi2DoStepTYPE *p_DoStep;
static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
static char guid[256], resources[4200];

#define CHECK(call)                                                            \
    do {                                                                       \
        fmi2Status s_ = (call);                                                \
        if (s_ != fmi2OK) {                                                    \
            fprintf(stderr, "%s returned %d\n", #call, (int)s_);              \
            exit(1);                                                           \
        }                                                                      \
    } while (0)

static double now(clockid_t clock) {
    struct timespec ts;
    clock_gettime(clock, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* VmRSS or VmHWM of this process in bytes, from /proc/self/status. */
static long status_bytes(const char *key) {
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long kb = -1;
    size_t n = strlen(key);
    if (!f) return -1;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, key, n) == 0 && line[n] == ':') {
            kb = strtol(line + n + 1, NULL, 10);
            break;
        }
    fclose(f);
    return kb * 1024;
}

static fmi2Component start(int k, double v_da, double x_s, double stop) {
    char name[64];
    snprintf(name, sizeof name, "bench_%d", k);
    fmi2Component c = p_Instantiate(name, fmi2CoSimulation, guid, resources, &callbacks, fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "p_Instantiate returned NULL (instance %d)\n", k);
        exit(1);
    }
    const fmi2ValueReference vr[2] = {VR_V_DA, VR_X_S};
    const fmi2Real u[2] = {v_da, x_s};
    CHECK(p_SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2True, stop));
    CHECK(p_EnterInitializationMode(c));
    CHECK(p_SetReal(c, vr, 2, u));
    CHECK(p_ExitInitializationMode(c));
    return c;
}

static void finish(fmi2Component c, double out[3]) {
    const fmi2ValueReference vr[3] = {VR_F_ACT, VR_P1, VR_P2};
    CHECK(p_GetReal(c, vr, 3, out));
    CHECK(p_Terminate(c));
    p_FreeInstance(c);
}

/* One run of `mode` on n instances in lockstep; prints its figures when `report`. */
static void run(const char *mode, int n, int report) {
    fmi2Component *c = calloc((size_t)n, sizeof *c);
    const fmi2ValueReference vr_in[2] = {VR_V_DA, VR_X_S};
    const fmi2ValueReference vr_f[1] = {VR_F_ACT};
    double out[3] = {0, 0, 0}, simulated, rms = 0.0;
    long calls = 0;
    double cpu0 = now(CLOCK_PROCESS_CPUTIME_ID), wall0 = now(CLOCK_MONOTONIC);
    if (strcmp(mode, "standard") == 0) {
        for (int i = 0; i < n; i++) c[i] = start(i, v_da_sample(0), x_s_sample(0), N_SAMPLES * SAMPLE);
        for (int k = 0; k < N_SAMPLES; k++) {
            const fmi2Real u[2] = {v_da_sample(k), x_s_sample(k)};
            double t = SAMPLE * k, t_next = SAMPLE * (k + 1);
            for (int i = 0; i < n; i++) {
                CHECK(p_SetReal(c[i], vr_in, 2, u));
                CHECK(p_DoStep(c[i], t, t_next - t, fmi2True));
                fmi2Real f;
                CHECK(p_GetReal(c[i], vr_f, 1, &f));
                if (i == 0) rms += f * f;
                calls += 3;
            }
        }
        simulated = N_SAMPLES * SAMPLE;
        rms = sqrt(rms / N_SAMPLES);
    } else if (strcmp(mode, "closedloop") == 0) {
        fmi2Real *force = calloc((size_t)n, sizeof *force);
        for (int i = 0; i < n; i++) {
            c[i] = start(i, CL_V_FF, 0.054, CL_STEPS * CL_STEP);
            CHECK(p_GetReal(c[i], vr_f, 1, &force[i]));
        }
        for (int k = 0; k < CL_STEPS; k++) {
            double t = k * CL_STEP;
            for (int i = 0; i < n; i++) {
                const fmi2Real v = closed_loop_command(t, force[i]);
                CHECK(p_SetReal(c[i], vr_in, 1, &v));
                CHECK(p_DoStep(c[i], t, CL_STEP, fmi2True));
                CHECK(p_GetReal(c[i], vr_f, 1, &force[i]));
                if (i == 0) {
                    double e = closed_loop_reference(t + CL_STEP) - force[i];
                    rms += e * e;
                }
                calls += 3;
            }
        }
        free(force);
        simulated = CL_STEPS * CL_STEP;
        rms = sqrt(rms / CL_STEPS);
    } else {
        fprintf(stderr, "unknown mode %s\n", mode);
        exit(2);
    }
    for (int i = 0; i < n; i++) finish(c[i], i == 0 ? out : (double[3]){0, 0, 0});
    double cpu = now(CLOCK_PROCESS_CPUTIME_ID) - cpu0, wall = now(CLOCK_MONOTONIC) - wall0;
    free(c);
    if (!report) return;
    printf("mode=%s\ninstances=%d\nsimulated_s=%.17g\n", mode, n, simulated);
    printf("cpu_s=%.9f\nwall_s=%.9f\nfmi_calls=%ld\n", cpu, wall, calls);
    printf("cpu_per_simulated_s_per_instance=%.9g\n", cpu / (simulated * n));
    printf("doSteps_per_wall_s=%.6g\n", calls / 3 / wall);
    printf("F_act=%.17g\nP1=%.17g\nP2=%.17g\n", out[0], out[1], out[2]);
    printf("%s=%.17g\n", strcmp(mode, "standard") == 0 ? "rms_F_act" : "rms_tracking_error", rms);
}

static void memory(int n) {
    /* One instance first: allocations made once per process (thread-locals, lazily built
     * tables, the allocator's first arenas) are not per-instance costs. */
    double out[3];
    fmi2Component warm = start(-1, 2.5, 0.054, 1.0);
    CHECK(p_DoStep(warm, 0.0, SAMPLE, fmi2True));
    finish(warm, out);
    long rss0 = status_bytes("VmRSS"), hwm0 = status_bytes("VmHWM");
    fmi2Component *c = calloc((size_t)n, sizeof *c);
    double t0 = now(CLOCK_MONOTONIC);
    for (int i = 0; i < n; i++) {
        c[i] = start(i, 2.5, 0.054, 1.0);
        CHECK(p_DoStep(c[i], 0.0, SAMPLE, fmi2True));
    }
    double setup_wall = now(CLOCK_MONOTONIC) - t0;
    long rss1 = status_bytes("VmRSS"), hwm1 = status_bytes("VmHWM");
    for (int i = 0; i < n; i++) finish(c[i], out);
    long rss2 = status_bytes("VmRSS");
    free(c);
    printf("mode=memory\ninstances=%d\n", n);
    printf("rss_before=%ld\nrss_with_instances=%ld\nrss_after_free=%ld\n", rss0, rss1, rss2);
    printf("hwm_before=%ld\nhwm_with_instances=%ld\n", hwm0, hwm1);
    printf("rss_bytes_per_instance=%.1f\n", (double)(rss1 - rss0) / n);
    printf("hwm_bytes_per_instance=%.1f\n", (double)(hwm1 - hwm0) / n);
    printf("setup_s_per_instance=%.9g\n", setup_wall / n);
}

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: %s EXTRACTED_FMU_DIR GUID standard|closedloop|memory N\n", argv[0]);
        return 2;
    }
    int n = atoi(argv[4]);
    if (n < 1) {
        fprintf(stderr, "N = %s is invalid: must be an integer >= 1\n", argv[4]);
        return 2;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/binaries/linux64/JetPipeActuator.so", argv[1]);
    snprintf(resources, sizeof resources, "file://%s/resources", argv[1]);
    snprintf(guid, sizeof guid, "%s", argv[2]);
    long rss_start = status_bytes("VmRSS");
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen failed: %s\n", dlerror());
        return 1;
    }
/* The pointers are named p_X, not fmi2X: fmi2Functions.h declares fmi2X as functions. */
#define RESOLVE(name)                                                          \
    p_##name = (fmi2##name##TYPE *)dlsym(lib, "fmi2" #name);                   \
    if (!p_##name) {                                                           \
        fprintf(stderr, "cannot resolve fmi2%s: %s\n", #name, dlerror());      \
        return 1;                                                              \
    }
    RESOLVE(Instantiate)
    RESOLVE(FreeInstance)
    RESOLVE(SetupExperiment)
    RESOLVE(EnterInitializationMode)
    RESOLVE(ExitInitializationMode)
    RESOLVE(Terminate)
    RESOLVE(SetReal)
    RESOLVE(GetReal)
    RESOLVE(DoStep)
    printf("rss_library_loaded=%ld\n", status_bytes("VmRSS") - rss_start);

    if (strcmp(argv[3], "memory") == 0) {
        memory(n);
    } else {
        run(argv[3], 1, 0); /* warm-up: first-use costs are not the model's per-step cost */
        run(argv[3], n, 1);
    }
    dlclose(lib);
    return 0;
}
