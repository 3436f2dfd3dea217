/*
 * A Model Exchange importer of the actuator FMU that builds for Linux (gcc) and for Windows
 * (MinGW-w64), for comparing the linux64 and win64 binaries through the Model Exchange calls
 * (issue 44): it loads the shared library given on the command line, resolves the FMI
 * functions by name with the types of the standard fmi2Functions.h, and integrates the first
 * second of the standard scenario (10 ms samples of v_DA and x_s, as src/scenario.rs defines
 * them) with the classical Runge-Kutta method at a fixed 10 us step: at each sample an event
 * (fmi2EnterEventMode, the new inputs, fmi2NewDiscreteStates, the states read again when they
 * changed, fmi2EnterContinuousTimeMode), between samples fmi2SetTime, fmi2SetContinuousStates,
 * fmi2GetDerivatives and fmi2CompletedIntegratorStep. It prints t, F_act, P1, P2, i and x_jp
 * before each sample's event (as a co-simulation master reads them) with 17 significant digits.
 *
 * usage: model_exchange_driver LIBRARY GUID
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE library_t;
#define OPEN(path) LoadLibraryA(path)
#define SYMBOL(lib, name) ((void *)GetProcAddress(lib, name))
#else
#include <dlfcn.h>
typedef void *library_t;
#define OPEN(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYMBOL(lib, name) dlsym(lib, name)
#endif

#include "fmi2Functions.h"

#define NX 31
#define NZ 8
#define SAMPLES 100
#define SUBSTEPS 1000 /* 10 us steps within a 10 ms sample */

static const fmi2ValueReference INPUTS[2] = {1u, 2u};            /* v_DA, x_s */
static const fmi2ValueReference OUTPUTS[5] = {10u, 11u, 12u, 13u, 14u}; /* F_act, P1, P2, i, x_jp */

static void logger(fmi2ComponentEnvironment env, fmi2String instanceName, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list args;
    (void)env;
    (void)category;
    fprintf(stderr, "[%d] %s: ", (int)status, instanceName ? instanceName : "");
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fprintf(stderr, "\n");
}

#define RESOLVE(name)                                                          \
    name##TYPE *name = (name##TYPE *)SYMBOL(lib, #name);                       \
    if (!name) {                                                               \
        fprintf(stderr, "cannot resolve %s\n", #name);                         \
        return 1;                                                              \
    }

#define CHECK(call)                                                            \
    do {                                                                       \
        fmi2Status s_ = (call);                                                \
        if (s_ != fmi2OK) {                                                    \
            fprintf(stderr, "%s returned %d\n", #call, (int)s_);              \
            return 1;                                                          \
        }                                                                      \
    } while (0)

static void inputs(int k, fmi2Real u[2]) {
    const double pi = 3.14159265358979323846;
    double t = 0.01 * k;
    u[0] = 2.5 + 3.0 * sin(2.0 * pi * 0.3 * t) + 0.5 * sin(2.0 * pi * 6.0 * t);
    u[1] = 0.054 + 0.01 * sin(2.0 * pi * 0.1 * t);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s LIBRARY GUID\n", argv[0]);
        return 2;
    }
    library_t lib = OPEN(argv[1]);
    if (!lib) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 1;
    }
    RESOLVE(fmi2Instantiate)
    RESOLVE(fmi2FreeInstance)
    RESOLVE(fmi2SetupExperiment)
    RESOLVE(fmi2EnterInitializationMode)
    RESOLVE(fmi2ExitInitializationMode)
    RESOLVE(fmi2Terminate)
    RESOLVE(fmi2SetReal)
    RESOLVE(fmi2GetReal)
    RESOLVE(fmi2EnterEventMode)
    RESOLVE(fmi2NewDiscreteStates)
    RESOLVE(fmi2EnterContinuousTimeMode)
    RESOLVE(fmi2CompletedIntegratorStep)
    RESOLVE(fmi2SetTime)
    RESOLVE(fmi2SetContinuousStates)
    RESOLVE(fmi2GetContinuousStates)
    RESOLVE(fmi2GetDerivatives)
    RESOLVE(fmi2GetEventIndicators)
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("me", fmi2ModelExchange, argv[2], "", &callbacks, fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate(fmi2ModelExchange) returned NULL\n");
        return 1;
    }
    fmi2Real u[2], y[5], x[NX], xs[NX], k1[NX], k2[NX], k3[NX], k4[NX], z[NZ];
    fmi2EventInfo info;
    fmi2Boolean enter, stop;
    const double h = 0.01 / SUBSTEPS;
    inputs(0, u);
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(fmi2EnterInitializationMode(c));
    CHECK(fmi2SetReal(c, INPUTS, 2, u));
    CHECK(fmi2ExitInitializationMode(c));
    printf("t,F_act,P1,P2,i,x_jp\n");
    for (int k = 0; k < SAMPLES; k++) {
        if (k > 0) {
            CHECK(fmi2EnterEventMode(c));
        }
        inputs(k, u);
        CHECK(fmi2SetReal(c, INPUTS, 2, u));
        CHECK(fmi2NewDiscreteStates(c, &info));
        CHECK(fmi2EnterContinuousTimeMode(c));
        CHECK(fmi2GetContinuousStates(c, x, NX));
        for (int j = 0; j < SUBSTEPS; j++) {
            double t = 0.01 * k + h * j;
#define RATE(time, state, out)                                                 \
    CHECK(fmi2SetTime(c, (time)));                                             \
    CHECK(fmi2SetContinuousStates(c, (state), NX));                            \
    CHECK(fmi2GetDerivatives(c, (out), NX));
            RATE(t, x, k1)
            for (int i = 0; i < NX; i++) xs[i] = x[i] + 0.5 * h * k1[i];
            RATE(t + 0.5 * h, xs, k2)
            for (int i = 0; i < NX; i++) xs[i] = x[i] + 0.5 * h * k2[i];
            RATE(t + 0.5 * h, xs, k3)
            for (int i = 0; i < NX; i++) xs[i] = x[i] + h * k3[i];
            RATE(t + h, xs, k4)
            for (int i = 0; i < NX; i++) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            CHECK(fmi2SetTime(c, 0.01 * k + h * (j + 1)));
            CHECK(fmi2SetContinuousStates(c, x, NX));
            CHECK(fmi2GetEventIndicators(c, z, NZ));
            CHECK(fmi2CompletedIntegratorStep(c, fmi2True, &enter, &stop));
        }
        CHECK(fmi2GetReal(c, OUTPUTS, 5, y));
        printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", 0.01 * (k + 1), y[0], y[1], y[2], y[3], y[4]);
    }
    CHECK(fmi2Terminate(c));
    fmi2FreeInstance(c);
    return 0;
}
