/*
 * An FMI 3.0 importer of the actuator FMU that builds for Linux (gcc) and for Windows
 * (MinGW-w64), for comparing the x86_64-linux and x86_64-windows binaries of
 * JetPipeActuator-fmi3.fmu (issue 44): it loads the shared library given on the command line and
 * resolves the fmi3 functions by name with the types of the standard fmi3Functions.h.
 *
 *  cs: fmi3InstantiateCoSimulation, the standard scenario's 10 ms samples of v_DA and x_s for
 *      10 s, ten fmi3DoStep of 1 ms each (what fmu_tests/c/scenario_driver.c does through FMI 2.0);
 *  me: fmi3InstantiateModelExchange, the first second with the classical Runge-Kutta method at a
 *      fixed 10 us step, an event at each sample (what fmu_tests/c/model_exchange_driver.c does
 *      through FMI 2.0).
 *
 * It prints t, F_act, P1, P2, i and x_jp at each sample with 17 significant digits.
 *
 * usage: fmi3_driver LIBRARY INSTANTIATION_TOKEN cs|me
 */
#include <math.h>
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

#include "fmi3Functions.h"

#define NX 31
#define NZ 8
#define SUBSTEPS 1000 /* 10 us steps within a 10 ms sample */

static const fmi3ValueReference INPUTS[2] = {1u, 2u};                   /* v_DA, x_s */
static const fmi3ValueReference OUTPUTS[5] = {10u, 11u, 12u, 13u, 14u}; /* F_act, P1, P2, i, x_jp */

static void log_message(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    fprintf(stderr, "[%d] [%s] %s\n", (int)status, category ? category : "", message ? message : "");
}

#define RESOLVE(name)                                                          \
    name##TYPE *name = (name##TYPE *)SYMBOL(lib, #name);                       \
    if (!name) {                                                               \
        fprintf(stderr, "cannot resolve %s\n", #name);                         \
        return 1;                                                              \
    }

#define CHECK(call)                                                            \
    do {                                                                       \
        fmi3Status s_ = (call);                                                \
        if (s_ != fmi3OK) {                                                    \
            fprintf(stderr, "%s returned %d\n", #call, (int)s_);              \
            return 1;                                                          \
        }                                                                      \
    } while (0)

static void inputs(int k, fmi3Float64 u[2]) {
    const double pi = 3.14159265358979323846;
    double t = 0.01 * k;
    u[0] = 2.5 + 3.0 * sin(2.0 * pi * 0.3 * t) + 0.5 * sin(2.0 * pi * 6.0 * t);
    u[1] = 0.054 + 0.01 * sin(2.0 * pi * 0.1 * t);
}

int main(int argc, char **argv) {
    if (argc != 4 || (strcmp(argv[3], "cs") != 0 && strcmp(argv[3], "me") != 0)) {
        fprintf(stderr, "usage: %s LIBRARY INSTANTIATION_TOKEN cs|me\n", argv[0]);
        return 2;
    }
    int me = strcmp(argv[3], "me") == 0;
    library_t lib = OPEN(argv[1]);
    if (!lib) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 1;
    }
    RESOLVE(fmi3GetVersion)
    RESOLVE(fmi3InstantiateCoSimulation)
    RESOLVE(fmi3InstantiateModelExchange)
    RESOLVE(fmi3FreeInstance)
    RESOLVE(fmi3EnterInitializationMode)
    RESOLVE(fmi3ExitInitializationMode)
    RESOLVE(fmi3Terminate)
    RESOLVE(fmi3SetFloat64)
    RESOLVE(fmi3GetFloat64)
    RESOLVE(fmi3DoStep)
    RESOLVE(fmi3EnterEventMode)
    RESOLVE(fmi3UpdateDiscreteStates)
    RESOLVE(fmi3EnterContinuousTimeMode)
    RESOLVE(fmi3CompletedIntegratorStep)
    RESOLVE(fmi3SetTime)
    RESOLVE(fmi3SetContinuousStates)
    RESOLVE(fmi3GetContinuousStates)
    RESOLVE(fmi3GetContinuousStateDerivatives)
    RESOLVE(fmi3GetEventIndicators)
    if (strcmp(fmi3GetVersion(), fmi3Version) != 0) {
        fprintf(stderr, "fmi3GetVersion: %s\n", fmi3GetVersion());
        return 1;
    }
    fmi3Instance c = me ? fmi3InstantiateModelExchange("me", argv[2], "", fmi3False, fmi3False, NULL, log_message)
                        : fmi3InstantiateCoSimulation("cs", argv[2], "", fmi3False, fmi3False, fmi3False, fmi3False,
                                                      NULL, 0, NULL, log_message, NULL);
    if (!c) {
        fprintf(stderr, "fmi3Instantiate%s returned NULL\n", me ? "ModelExchange" : "CoSimulation");
        return 1;
    }
    fmi3Float64 u[2], y[5];
    inputs(0, u);
    CHECK(fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0));
    CHECK(fmi3SetFloat64(c, INPUTS, 2, u, 2));
    CHECK(fmi3ExitInitializationMode(c));
    printf("t,F_act,P1,P2,i,x_jp\n");
    if (!me) {
        double t = 0.0;
        fmi3Boolean event, terminate, early;
        fmi3Float64 reached;
        for (int k = 0; k < 1000; k++) {
            inputs(k, u);
            CHECK(fmi3SetFloat64(c, INPUTS, 2, u, 2));
            for (int j = 0; j < 10; j++) {
                CHECK(fmi3DoStep(c, t, 1e-3, fmi3True, &event, &terminate, &early, &reached));
                if (event || terminate || early || fabs(reached - (t + 1e-3)) > 1e-9) {
                    fprintf(stderr, "fmi3DoStep: unexpected flags or lastSuccessfulTime %.17g\n", reached);
                    return 1;
                }
                t = 0.01 * k + 1e-3 * (j + 1);
            }
            CHECK(fmi3GetFloat64(c, OUTPUTS, 5, y, 5));
            printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", t, y[0], y[1], y[2], y[3], y[4]);
        }
    } else {
        fmi3Float64 x[NX], xs[NX], k1[NX], k2[NX], k3[NX], k4[NX], z[NZ], next;
        fmi3Boolean update, stop, nominals, values, defined, enter;
        const double h = 0.01 / SUBSTEPS;
        for (int k = 0; k < 100; k++) {
            if (k > 0) {
                CHECK(fmi3EnterEventMode(c));
            }
            inputs(k, u);
            CHECK(fmi3SetFloat64(c, INPUTS, 2, u, 2));
            CHECK(fmi3UpdateDiscreteStates(c, &update, &stop, &nominals, &values, &defined, &next));
            CHECK(fmi3EnterContinuousTimeMode(c));
            CHECK(fmi3GetContinuousStates(c, x, NX));
            for (int j = 0; j < SUBSTEPS; j++) {
                double t = 0.01 * k + h * j;
#define RATE(time, state, out)                                                 \
    CHECK(fmi3SetTime(c, (time)));                                             \
    CHECK(fmi3SetContinuousStates(c, (state), NX));                            \
    CHECK(fmi3GetContinuousStateDerivatives(c, (out), NX));
                RATE(t, x, k1)
                for (int i = 0; i < NX; i++) xs[i] = x[i] + 0.5 * h * k1[i];
                RATE(t + 0.5 * h, xs, k2)
                for (int i = 0; i < NX; i++) xs[i] = x[i] + 0.5 * h * k2[i];
                RATE(t + 0.5 * h, xs, k3)
                for (int i = 0; i < NX; i++) xs[i] = x[i] + h * k3[i];
                RATE(t + h, xs, k4)
                for (int i = 0; i < NX; i++) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                CHECK(fmi3SetTime(c, 0.01 * k + h * (j + 1)));
                CHECK(fmi3SetContinuousStates(c, x, NX));
                CHECK(fmi3GetEventIndicators(c, z, NZ));
                CHECK(fmi3CompletedIntegratorStep(c, fmi3True, &enter, &stop));
            }
            CHECK(fmi3GetFloat64(c, OUTPUTS, 5, y, 5));
            printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", 0.01 * (k + 1), y[0], y[1], y[2], y[3], y[4]);
        }
    }
    CHECK(fmi3Terminate(c));
    fmi3FreeInstance(c);
    return 0;
}
