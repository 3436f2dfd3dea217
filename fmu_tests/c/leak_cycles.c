/*
 * Leak and memory-error check of the JetPipeActuator FMU from a plain C importer
 * (issue 5): N cycles of instantiate / setup / initialise / step / FMU state get, serialize,
 * deserialize, set, free / terminate / reset / free, with error paths on the way (illegal
 * calls, rejected values, corrupted state bytes, NULL and freed handles, repeated
 * fmi2FreeInstance, failed fmi2Instantiate); and in each cycle a Model Exchange instance
 * (issue 44): initialise, event and continuous-time modes, states, derivatives, event
 * indicators, an FMU state, illegal calls, a refused effect. Meant to run under Valgrind or
 * LeakSanitizer.
 *
 * usage: leak_cycles EXTRACTED_FMU_DIR GUID N_CYCLES [--leak-one]
 * --leak-one skips one fmi2FreeInstance on purpose: the negative control that shows the
 * leak checker sees the FMU's allocations.
 * Prints a summary line; exit status 0 when every status was the expected one, 1 otherwise.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define VR_V_DA 1u
#define VR_X_S 2u
#define VR_F_ACT 10u
#define VR_P1 11u
#define VR_P2 12u

static long n_messages = 0, n_error_messages = 0;

/* A real variadic logger: formats the message like an importer would. */
static void logger(fmi2ComponentEnvironment env, fmi2String instanceName, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    char buf[2048];
    va_list args;
    (void)env;
    (void)instanceName;
    (void)category;
    va_start(args, message);
    vsnprintf(buf, sizeof buf, message, args);
    va_end(args);
    n_messages++;
    if (status >= fmi2Error) n_error_messages++;
}

#define RESOLVE(name)                                                          \
    name##TYPE *name = (name##TYPE *)dlsym(lib, #name);                        \
    if (!name) {                                                               \
        fprintf(stderr, "cannot resolve %s: %s\n", #name, dlerror());          \
        return 1;                                                              \
    }

#define EXPECT(call, want)                                                     \
    do {                                                                       \
        fmi2Status s_ = (call);                                                \
        if (s_ != (want)) {                                                    \
            fprintf(stderr, "cycle %d: %s returned %d, expected %d\n", k,      \
                    #call, (int)s_, (int)(want));                              \
            return 1;                                                          \
        }                                                                      \
    } while (0)

int main(int argc, char **argv) {
    if (argc != 4 && !(argc == 5 && strcmp(argv[4], "--leak-one") == 0)) {
        fprintf(stderr, "usage: %s EXTRACTED_FMU_DIR GUID N_CYCLES [--leak-one]\n", argv[0]);
        return 2;
    }
    const int leak_one = argc == 5;
    const char *dir = argv[1];
    const char *guid = argv[2];
    const int n = atoi(argv[3]);
    char path[4096], resources[4200];
    snprintf(path, sizeof path, "%s/binaries/linux64/JetPipeActuator.so", dir);
    snprintf(resources, sizeof resources, "file://%s/resources", dir);

    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen failed: %s\n", dlerror());
        return 1;
    }
    RESOLVE(fmi2Instantiate)
    RESOLVE(fmi2FreeInstance)
    RESOLVE(fmi2SetupExperiment)
    RESOLVE(fmi2EnterInitializationMode)
    RESOLVE(fmi2ExitInitializationMode)
    RESOLVE(fmi2Terminate)
    RESOLVE(fmi2Reset)
    RESOLVE(fmi2SetReal)
    RESOLVE(fmi2GetReal)
    RESOLVE(fmi2DoStep)
    RESOLVE(fmi2GetFMUstate)
    RESOLVE(fmi2SetFMUstate)
    RESOLVE(fmi2FreeFMUstate)
    RESOLVE(fmi2SerializedFMUstateSize)
    RESOLVE(fmi2SerializeFMUstate)
    RESOLVE(fmi2DeSerializeFMUstate)
    RESOLVE(fmi2SetDebugLogging)
    RESOLVE(fmi2SetRealInputDerivatives)
    RESOLVE(fmi2EnterEventMode)
    RESOLVE(fmi2NewDiscreteStates)
    RESOLVE(fmi2EnterContinuousTimeMode)
    RESOLVE(fmi2CompletedIntegratorStep)
    RESOLVE(fmi2SetTime)
    RESOLVE(fmi2SetContinuousStates)
    RESOLVE(fmi2GetContinuousStates)
    RESOLVE(fmi2GetDerivatives)
    RESOLVE(fmi2GetEventIndicators)
    RESOLVE(fmi2GetNominalsOfContinuousStates)

    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    const fmi2ValueReference vr_in[2] = {VR_V_DA, VR_X_S};
    const fmi2ValueReference vr_out[3] = {VR_F_ACT, VR_P1, VR_P2};
    const fmi2ValueReference vr_bad[1] = {9999u};
    long steps = 0;
    size_t state_bytes = 0;
    double f_sum = 0.0;
    int k;

    for (k = 0; k < n; k++) {
        fmi2Component c = fmi2Instantiate("cycle", fmi2CoSimulation, guid, resources, &callbacks, fmi2False,
                                          (k % 2) ? fmi2True : fmi2False);
        if (!c) {
            fprintf(stderr, "cycle %d: fmi2Instantiate returned NULL\n", k);
            return 1;
        }
        const fmi2Real in[2] = {1.0 + 0.004 * (k % 1000), 0.04 + 0.00002 * (k % 1000)};
        const fmi2Real nan_in[1] = {NAN};
        fmi2Real out[3];

        /* error paths before initialisation */
        EXPECT(fmi2DoStep(c, 0.0, 1e-3, fmi2True), fmi2Error);
        EXPECT(fmi2GetReal(c, vr_bad, 1, out), fmi2Error);
        EXPECT(fmi2GetReal(c, vr_out, 1, out), fmi2Error); /* outputs have no value yet */

        EXPECT(fmi2SetupExperiment(c, fmi2True, 1e-6, 0.0, fmi2False, 0.0), fmi2OK);
        EXPECT(fmi2EnterInitializationMode(c), fmi2OK);
        EXPECT(fmi2SetReal(c, vr_in, 2, in), fmi2OK);
        EXPECT(fmi2SetReal(c, vr_in, 1, nan_in), fmi2Error);
        EXPECT(fmi2ExitInitializationMode(c), fmi2OK);

        double t = 0.0;
        for (int j = 0; j < 3; j++) {
            EXPECT(fmi2DoStep(c, t, 1e-3, fmi2True), fmi2OK);
            t += 1e-3;
            steps++;
        }
        EXPECT(fmi2GetReal(c, vr_out, 3, out), fmi2OK);
        f_sum += out[0];

        /* FMU state: get, serialize, deserialize (good and corrupted), set, free */
        fmi2FMUstate st = NULL, st2 = NULL, bad = NULL;
        EXPECT(fmi2GetFMUstate(c, &st), fmi2OK);
        EXPECT(fmi2GetFMUstate(c, &st), fmi2OK); /* overwrite in place */
        size_t size = 0;
        EXPECT(fmi2SerializedFMUstateSize(c, st, &size), fmi2OK);
        fmi2Byte *bytes = malloc(size);
        EXPECT(fmi2SerializeFMUstate(c, st, bytes, size), fmi2OK);
        EXPECT(fmi2SerializeFMUstate(c, st, bytes, size - 1), fmi2Error);
        EXPECT(fmi2DeSerializeFMUstate(c, bytes, size, &st2), fmi2OK);
        bytes[size / 2] ^= 0x20;
        EXPECT(fmi2DeSerializeFMUstate(c, bytes, size, &bad), fmi2Error);
        EXPECT(fmi2DeSerializeFMUstate(c, bytes, size / 3, &bad), fmi2Error);
        state_bytes += size;
        free(bytes);
        EXPECT(fmi2DoStep(c, t, 1e-3, fmi2True), fmi2OK);
        EXPECT(fmi2SetFMUstate(c, st2), fmi2OK);
        EXPECT(fmi2FreeFMUstate(c, &st2), fmi2OK);
        fmi2FMUstate copy = st;
        EXPECT(fmi2FreeFMUstate(c, &st), fmi2OK);
        EXPECT(fmi2SetFMUstate(c, copy), fmi2Error); /* freed FMU state */

        /* input derivative, a step with it */
        const fmi2Integer order[1] = {1};
        const fmi2Real der[1] = {0.01};
        EXPECT(fmi2SetRealInputDerivatives(c, &vr_in[1], 1, order, der), fmi2OK);
        EXPECT(fmi2DoStep(c, t, 1e-3, fmi2True), fmi2OK);
        steps++;

        if (k % 3 == 0) {
            EXPECT(fmi2SetDebugLogging(c, fmi2True, 0, NULL), fmi2OK);
            EXPECT(fmi2Reset(c), fmi2OK); /* then free from instantiated */
        } else {
            EXPECT(fmi2Terminate(c), fmi2OK);
            EXPECT(fmi2DoStep(c, t + 1e-3, 1e-3, fmi2True), fmi2Error); /* illegal after terminate */
        }
        if (leak_one && k == 0) continue; /* the deliberate leak */
        fmi2FreeInstance(c);

        /* Model Exchange: a few explicit Euler steps through the calls an integrator makes */
        fmi2Component m = fmi2Instantiate("me", fmi2ModelExchange, guid, resources, &callbacks, fmi2False,
                                          (k % 2) ? fmi2True : fmi2False);
        if (!m) {
            fprintf(stderr, "cycle %d: fmi2Instantiate(fmi2ModelExchange) returned NULL\n", k);
            return 1;
        }
        {
            fmi2Real x[31], dx[31], z[8], nominal[31];
            fmi2EventInfo info;
            fmi2Boolean enter = fmi2True, stop = fmi2True;
            /* current_slew_limit: refused in Model Exchange when set (command_delay is refused
               only when initialisation ends, after its Pade sections may have been set) */
            const fmi2ValueReference vr_refused[1] = {453u};
            const fmi2Real refused[1] = {1e3};
            EXPECT(fmi2GetNominalsOfContinuousStates(m, nominal, 31), fmi2OK);
            EXPECT(fmi2SetupExperiment(m, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
            EXPECT(fmi2EnterInitializationMode(m), fmi2OK);
            EXPECT(fmi2SetReal(m, vr_refused, 1, refused), fmi2Error);
            EXPECT(fmi2SetReal(m, vr_in, 2, in), fmi2OK);
            EXPECT(fmi2ExitInitializationMode(m), fmi2OK);
            EXPECT(fmi2NewDiscreteStates(m, &info), fmi2OK);
            EXPECT(fmi2DoStep(m, 0.0, 1e-3, fmi2True), fmi2Error); /* a Co-Simulation call */
            EXPECT(fmi2EnterContinuousTimeMode(m), fmi2OK);
            EXPECT(fmi2GetContinuousStates(m, x, 31), fmi2OK);
            EXPECT(fmi2GetContinuousStates(m, x, 6), fmi2Error);
            for (int j = 0; j < 5; j++) {
                EXPECT(fmi2SetTime(m, j * 1e-6), fmi2OK);
                EXPECT(fmi2SetContinuousStates(m, x, 31), fmi2OK);
                EXPECT(fmi2GetDerivatives(m, dx, 31), fmi2OK);
                EXPECT(fmi2GetEventIndicators(m, z, 8), fmi2OK);
                EXPECT(fmi2CompletedIntegratorStep(m, fmi2True, &enter, &stop), fmi2OK);
                for (int i = 0; i < 31; i++) x[i] += 1e-6 * dx[i];
            }
            EXPECT(fmi2EnterEventMode(m), fmi2OK);
            EXPECT(fmi2SetReal(m, vr_in, 2, in), fmi2OK);
            EXPECT(fmi2NewDiscreteStates(m, &info), fmi2OK);
            fmi2FMUstate ms = NULL;
            EXPECT(fmi2GetFMUstate(m, &ms), fmi2OK);
            EXPECT(fmi2EnterContinuousTimeMode(m), fmi2OK);
            EXPECT(fmi2SetFMUstate(m, ms), fmi2OK);
            EXPECT(fmi2FreeFMUstate(m, &ms), fmi2OK);
            if (k % 2) {
                EXPECT(fmi2Terminate(m), fmi2OK);
            } else {
                EXPECT(fmi2Reset(m), fmi2OK);
            }
        }
        fmi2FreeInstance(m);
        if (k % 10 == 0) {
            fmi2FreeInstance(c); /* repeated: must be harmless */
            EXPECT(fmi2Reset(c), fmi2Error);
            fmi2FreeInstance(NULL);
            EXPECT(fmi2DoStep(NULL, 0.0, 1e-3, fmi2True), fmi2Error);
            /* failed instantiations */
            if (fmi2Instantiate("bad", fmi2CoSimulation, "{not-the-guid}", resources, &callbacks, fmi2False, fmi2False) ||
                fmi2Instantiate("me", fmi2ModelExchange, "{not-the-guid}", resources, &callbacks, fmi2False, fmi2False) ||
                fmi2Instantiate(NULL, fmi2CoSimulation, guid, resources, &callbacks, fmi2False, fmi2False) ||
                fmi2Instantiate("nocb", fmi2CoSimulation, guid, resources, NULL, fmi2False, fmi2False)) {
                fprintf(stderr, "cycle %d: a bad fmi2Instantiate returned an instance\n", k);
                return 1;
            }
        }
    }
    if (n_error_messages == 0 && n > 0) {
        fprintf(stderr, "no error message was logged\n");
        return 1;
    }
    printf("cycles=%d steps=%ld messages=%ld error_messages=%ld state_bytes=%zu mean_F_act=%.6g\n", n, steps,
           n_messages, n_error_messages, state_bytes, n > 0 ? f_sum / n : 0.0);
    dlclose(lib);
    return 0;
}
