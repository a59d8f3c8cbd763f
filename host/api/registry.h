// The one list of methods: each one's name, its front end's factory (the front end holds
// its summary and parameter table), where the single-method paths pick it, and the
// variants `auto` runs of it, with their parameters, run order and map colour. The method
// names, the front ends by name, auto's candidates, pick order and palette all derive from
// it; a new method is one entry here (registry.cpp) and its own files.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "host/api/front_end.h"

namespace mcd::api {

// One candidate of auto: the method with some parameters set over the user's.
struct AutoVariant {
    std::string label;  // what --explain and the stages call it ("pivot k0")
    std::vector<std::pair<std::string, ParamValue>> overrides;
    int order = 0;                // auto runs the variants of all methods by this, lowest first
    float colour[3] = {0, 0, 0};  // in the map of the largest weights (linear RGB)
    std::string colourName;
    // Layers without which the variant filters as its method's own parameters do (none of
    // them on the frame: the variant is left out). Empty: it always differs.
    std::vector<std::string> differsWith;
    // The error estimates under which it runs (bits of Estimate): the half-buffers', SURE
    // on the variance layer, SURE on the frame's own. Where one is off, SURE misjudged the
    // variant there, or beside the candidates that run there it did not earn its time.
    // docs/methods/auto.md has the measurements.
    enum Estimate : unsigned { kHalves = 1, kVariance = 2, kOwn = 4, kAnyEstimate = 7 };
    unsigned estimates = kAnyEstimate;
    // Sets the probe's parameters over the run's (its run on half0 or on the perturbed
    // colour): a cheaper probe where its estimate weighed the candidates as well. Null: the
    // probe runs as the run does.
    void (*cheaperProbe)(FrontEnd &method) = nullptr;
    // Runs only where --auto-candidates names it: beside the others it held small shares
    // and cost much time (docs/methods/auto.md).
    bool byDefault = true;
};

struct MethodEntry {
    std::string name;
    std::unique_ptr<FrontEnd> (*make)();
    // The single-method paths (--demodulate, the CPU reference) take the first method the
    // frame allows by this, lowest first; -1: never picked.
    int pick = -1;
    std::vector<AutoVariant> variants;  // empty: auto does not run it
    // Parameters auto sets for every variant of the method where the user did not set them
    // and an error estimate weighs the candidates (not under --auto-combine mean), before
    // the variant's own overrides (which mark a variant; these do not), and why (the plan).
    std::vector<std::pair<std::string, ParamValue>> autoSettings;
    std::string autoSettingsWhy;
};

// The methods, in the order the command line lists them.
const std::vector<MethodEntry> &Registry();

// The entry named `name`, or null.
const MethodEntry *FindMethod(const std::string &name);

// auto's candidates in run order: each variant with its method.
struct RegisteredVariant {
    const MethodEntry *method;
    const AutoVariant *variant;
};
std::vector<RegisteredVariant> AutoVariants();

// The methods the single-method paths pick from, in pick order.
std::vector<const MethodEntry *> PickOrder();

}  // namespace mcd::api
