/*
 * Leak and memory-error check of the FMI 3.0 interface of the JetPipeActuator FMU from a plain
 * C importer (issue 44): N cycles of, for Co-Simulation, instantiate / initialise / steps / FMU
 * state get, serialize, deserialize, set, free / terminate / reset / free, and for Model
 * Exchange, instantiate / initialise / event and continuous-time modes / states, derivatives,
 * event indicators / an FMU state / free; with error paths on the way
 * (illegal calls, unsupported calls, rejected values, corrupted state bytes, an FMI 2.0 call on
 * an FMI 3.0 instance, NULL and freed handles, repeated fmi3FreeInstance, failed
 * instantiation). Meant to run under Valgrind or LeakSanitizer.
 *
 * usage: leak_cycles_fmi3 LIBRARY INSTANTIATION_TOKEN N_CYCLES [--leak-one]
 * --leak-one skips one fmi3FreeInstance on purpose: the negative control that shows the leak
 * checker sees the FMU's allocations.
 * Prints a summary line; exit status 0 when every status was the expected one, 1 otherwise.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"

#define VR_V_DA 1u
#define VR_X_S 2u
#define VR_F_ACT 10u
#define VR_P1 11u
#define VR_P2 12u
#define NX 31
#define NZ 8

static long n_messages = 0, n_error_messages = 0;

static void log_message(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    char buf[2048];
    (void)env;
    (void)category;
    snprintf(buf, sizeof buf, "%s", message);
    n_messages++;
    if (status >= fmi3Error) n_error_messages++;
}

#define RESOLVE(name)                                                          \
    name##TYPE *name = (name##TYPE *)dlsym(lib, #name);                        \
    if (!name) {                                                               \
        fprintf(stderr, "cannot resolve %s: %s\n", #name, dlerror());          \
        return 1;                                                              \
    }

#define EXPECT(call, want)                                                     \
    do {                                                                       \
        int s_ = (int)(call);                                                  \
        if (s_ != (int)(want)) {                                               \
            fprintf(stderr, "cycle %d: %s returned %d, expected %d\n", k,      \
                    #call, s_, (int)(want));                                   \
            return 1;                                                          \
        }                                                                      \
    } while (0)

typedef int fmi2TerminateTYPE(void *c);

int main(int argc, char **argv) {
    if (argc != 4 && !(argc == 5 && strcmp(argv[4], "--leak-one") == 0)) {
        fprintf(stderr, "usage: %s LIBRARY INSTANTIATION_TOKEN N_CYCLES [--leak-one]\n", argv[0]);
        return 2;
    }
    const int leak_one = argc == 5;
    const char *token = argv[2];
    const int n = atoi(argv[3]);
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen failed: %s\n", dlerror());
        return 1;
    }
    RESOLVE(fmi3InstantiateCoSimulation)
    RESOLVE(fmi3InstantiateModelExchange)
    RESOLVE(fmi3InstantiateScheduledExecution)
    RESOLVE(fmi3FreeInstance)
    RESOLVE(fmi3SetDebugLogging)
    RESOLVE(fmi3EnterInitializationMode)
    RESOLVE(fmi3ExitInitializationMode)
    RESOLVE(fmi3Terminate)
    RESOLVE(fmi3Reset)
    RESOLVE(fmi3SetFloat64)
    RESOLVE(fmi3GetFloat64)
    RESOLVE(fmi3GetFloat32)
    RESOLVE(fmi3DoStep)
    RESOLVE(fmi3EnterStepMode)
    RESOLVE(fmi3GetFMUState)
    RESOLVE(fmi3SetFMUState)
    RESOLVE(fmi3FreeFMUState)
    RESOLVE(fmi3SerializedFMUStateSize)
    RESOLVE(fmi3SerializeFMUState)
    RESOLVE(fmi3DeserializeFMUState)
    RESOLVE(fmi3GetDirectionalDerivative)
    RESOLVE(fmi3EnterEventMode)
    RESOLVE(fmi3UpdateDiscreteStates)
    RESOLVE(fmi3EnterContinuousTimeMode)
    RESOLVE(fmi3CompletedIntegratorStep)
    RESOLVE(fmi3SetTime)
    RESOLVE(fmi3SetContinuousStates)
    RESOLVE(fmi3GetContinuousStates)
    RESOLVE(fmi3GetContinuousStateDerivatives)
    RESOLVE(fmi3GetEventIndicators)
    RESOLVE(fmi3GetNominalsOfContinuousStates)
    fmi2TerminateTYPE *fmi2Terminate = (fmi2TerminateTYPE *)dlsym(lib, "fmi2Terminate");
    if (!fmi2Terminate) {
        fprintf(stderr, "cannot resolve fmi2Terminate\n");
        return 1;
    }
    const fmi3ValueReference vr_in[2] = {VR_V_DA, VR_X_S};
    const fmi3ValueReference vr_out[3] = {VR_F_ACT, VR_P1, VR_P2};
    long steps = 0, rhs = 0;
    size_t state_bytes = 0;
    double f_sum = 0.0;
    int k;
    for (k = 0; k < n; k++) {
        /* a failed instantiation: wrong token, event mode, Scheduled Execution */
        if (fmi3InstantiateCoSimulation("bad", "{wrong}", "", fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, NULL,
                                        log_message, NULL) != NULL ||
            fmi3InstantiateCoSimulation("bad", token, "", fmi3False, fmi3False, fmi3True, fmi3False, NULL, 0, NULL,
                                        log_message, NULL) != NULL ||
            fmi3InstantiateScheduledExecution("bad", token, "", fmi3False, fmi3False, NULL, log_message, NULL, NULL,
                                              NULL) != NULL) {
            fprintf(stderr, "cycle %d: a bad instantiation gave an instance\n", k);
            return 1;
        }

        /* Co-Simulation */
        fmi3Instance c = fmi3InstantiateCoSimulation("cs", token, "", fmi3False, k % 2 == 0, fmi3False, fmi3False,
                                                     NULL, 0, NULL, log_message, NULL);
        if (!c) {
            fprintf(stderr, "cycle %d: fmi3InstantiateCoSimulation returned NULL\n", k);
            return 1;
        }
        fmi3Float64 u[2] = {2.5, 0.054}, y[3], bad[1] = {NAN};
        fmi3Boolean event, terminate, early;
        fmi3Float64 reached;
        EXPECT(fmi3SetDebugLogging(c, fmi3True, 0, NULL), fmi3OK);
        EXPECT(fmi3DoStep(c, 0.0, 1e-3, fmi3True, &event, &terminate, &early, &reached), fmi3Error); /* illegal */
        EXPECT(fmi3GetFloat64(c, vr_out, 3, y, 3), fmi3Error); /* no outputs yet */
        EXPECT(fmi3SetFloat64(c, vr_in, 2, u, 2), fmi3OK);
        EXPECT(fmi3SetFloat64(c, vr_in, 1, bad, 1), fmi3Error);
        EXPECT(fmi3EnterInitializationMode(c, fmi3True, 1e-6, 0.0, fmi3False, 0.0), fmi3OK);
        EXPECT(fmi3ExitInitializationMode(c), fmi3OK);
        EXPECT(fmi3EnterStepMode(c), fmi3Error);
        EXPECT(fmi3GetFloat32(c, vr_in, 1, (fmi3Float32 *)y, 1), fmi3Error);
        EXPECT(fmi3GetDirectionalDerivative(c, vr_out, 1, vr_in, 1, u, 1, y, 1), fmi3Error);
        EXPECT(fmi2Terminate(c), 3); /* fmi2Error: an FMI 3.0 instance */
        double t = 0.0;
        u[0] = 6.0;
        EXPECT(fmi3SetFloat64(c, vr_in, 1, u, 1), fmi3OK);
        fmi3FMUState s = NULL, s2 = NULL;
        EXPECT(fmi3GetFMUState(c, &s), fmi3OK);
        for (int j = 0; j < 10; j++) {
            EXPECT(fmi3DoStep(c, t, 1e-3, fmi3True, &event, &terminate, &early, &reached), fmi3OK);
            t += 1e-3;
            steps++;
        }
        EXPECT(fmi3GetFloat64(c, vr_out, 3, y, 3), fmi3OK);
        f_sum += y[0];
        size_t size = 0;
        EXPECT(fmi3SerializedFMUStateSize(c, s, &size), fmi3OK);
        fmi3Byte *bytes = (fmi3Byte *)malloc(size);
        EXPECT(fmi3SerializeFMUState(c, s, bytes, size), fmi3OK);
        state_bytes += size;
        bytes[size / 2] ^= 0x5a;
        EXPECT(fmi3DeserializeFMUState(c, bytes, size, &s2), fmi3Error); /* corrupted */
        bytes[size / 2] ^= 0x5a;
        EXPECT(fmi3DeserializeFMUState(c, bytes, size, &s2), fmi3OK);
        EXPECT(fmi3DeserializeFMUState(c, bytes, size, &s2), fmi3OK); /* into the same state */
        free(bytes);
        EXPECT(fmi3SetFMUState(c, s2), fmi3OK);
        EXPECT(fmi3FreeFMUState(c, &s), fmi3OK);
        EXPECT(fmi3FreeFMUState(c, &s2), fmi3OK);
        EXPECT(fmi3FreeFMUState(c, &s2), fmi3OK); /* NULL: a no-op */
        EXPECT(fmi3Terminate(c), fmi3OK);
        EXPECT(fmi3Reset(c), fmi3OK);
        if (!(leak_one && k == 0)) {
            fmi3FreeInstance(c);
            fmi3FreeInstance(c); /* a second free is refused without touching the memory */
            EXPECT(fmi3Terminate(c), fmi3Error);
        }

        /* Model Exchange */
        fmi3Instance m = fmi3InstantiateModelExchange("me", token, "", fmi3False, fmi3False, NULL, log_message);
        if (!m) {
            fprintf(stderr, "cycle %d: fmi3InstantiateModelExchange returned NULL\n", k);
            return 1;
        }
        fmi3Float64 x[NX], dx[NX], z[NZ], nominal[NX], next;
        fmi3Boolean update, stop, nominals, values, defined, enter;
        EXPECT(fmi3DoStep(m, 0.0, 1e-3, fmi3True, &event, &terminate, &early, &reached), fmi3Error);
        EXPECT(fmi3SetFloat64(m, vr_in, 2, u, 2), fmi3OK);
        EXPECT(fmi3EnterInitializationMode(m, fmi3False, 0.0, 0.0, fmi3False, 0.0), fmi3OK);
        EXPECT(fmi3ExitInitializationMode(m), fmi3OK);
        EXPECT(fmi3UpdateDiscreteStates(m, &update, &stop, &nominals, &values, &defined, &next), fmi3OK);
        EXPECT(fmi3EnterContinuousTimeMode(m), fmi3OK);
        EXPECT(fmi3GetContinuousStates(m, x, NX), fmi3OK);
        EXPECT(fmi3GetNominalsOfContinuousStates(m, nominal, NX), fmi3OK);
        EXPECT(fmi3GetContinuousStates(m, x, NX - 1), fmi3Error);
        EXPECT(fmi3UpdateDiscreteStates(m, &update, &stop, &nominals, &values, &defined, &next), fmi3Error);
        for (int j = 1; j <= 10; j++) {
            EXPECT(fmi3SetTime(m, 1e-5 * j), fmi3OK);
            EXPECT(fmi3GetContinuousStateDerivatives(m, dx, NX), fmi3OK);
            for (int i = 0; i < NX; i++) x[i] += 1e-5 * dx[i];
            EXPECT(fmi3SetContinuousStates(m, x, NX), fmi3OK);
            EXPECT(fmi3GetEventIndicators(m, z, NZ), fmi3OK);
            EXPECT(fmi3CompletedIntegratorStep(m, fmi3True, &enter, &stop), fmi3OK);
            rhs++;
        }
        x[4] = -1.0;
        EXPECT(fmi3SetContinuousStates(m, x, NX), fmi3Error); /* a negative pressure */
        EXPECT(fmi3GetFMUState(m, &s), fmi3OK);
        EXPECT(fmi3EnterEventMode(m), fmi3OK);
        EXPECT(fmi3SetFMUState(m, s), fmi3OK);
        EXPECT(fmi3FreeFMUState(m, &s), fmi3OK);
        EXPECT(fmi3Terminate(m), fmi3OK);
        fmi3FreeInstance(m);
    }
    printf("cycles=%d steps=%ld rhs=%ld state_bytes=%zu messages=%ld error_messages=%ld mean_F_act=%.6f\n", n, steps,
           rhs, state_bytes, n_messages, n_error_messages, n > 0 ? f_sum / n : 0.0);
    dlclose(lib);
    return 0;
}
