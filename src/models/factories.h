#pragma once
// The entry points of the models, one per source file, listed in the registry table
// (registry.cpp). A new model adds one function here and one line there.

#include "models/model.h"

#include <memory>
#include <vector>

namespace lamina {

// ww09.cpp, ele10.cpp, ww_prime.cpp
std::unique_ptr<Model> make_ww09(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> ww09_options();
std::unique_ptr<Model> make_ele10(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> ele10_options();
std::unique_ptr<Model> make_ww_prime(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> ww_prime_options();

// bel18_forward.cpp, bel18_symmetric.cpp, bel_prime.cpp
std::unique_ptr<Model> make_bel18_forward(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> bel18_forward_options();
std::unique_ptr<Model> make_bel18_symmetric(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> bel18_symmetric_options();
std::unique_ptr<Model> make_bel_prime(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> bel_prime_options();

// lamina1.cpp: lamina's own layered model (docs/models.md, "lamina-1")
std::unique_ptr<Model> make_lamina1(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> lamina1_options();

// random_walk_model.cpp: the per-query stochastic reference (randomwalk/random_walk.h)
std::unique_ptr<Model> make_random_walk(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> random_walk_options();

}  // namespace lamina
