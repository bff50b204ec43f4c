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

// tm2.cpp: the transfer-matrix model (Randrianandrasana, Callet & Lucas 2021)
std::unique_ptr<Model> make_tm2(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> tm2_options();
// tm6.cpp: the same with Henyey–Greenstein media (the released plugin tm6)
std::unique_ptr<Model> make_tm6(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> tm6_options();
// ddb22.cpp: lamina's reading of de Dinechin & Belcour 2022 (a rough coat over a Lambertian)
std::unique_ptr<Model> make_ddb22(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> ddb22_options();
// lamina1.cpp: lamina's own layered model (docs/models.md, "lamina-1")
std::unique_ptr<Model> make_lamina1(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> lamina1_options();

// random_walk_model.cpp: the per-query stochastic reference (randomwalk/random_walk.h)
std::unique_ptr<Model> make_random_walk(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> random_walk_options();

// production_coats.cpp: the coats engines ship (models/production_coat.h)
std::unique_ptr<Model> make_openpbr(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> openpbr_options();
std::unique_ptr<Model> make_openpbr_adobe(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> openpbr_adobe_options();
std::unique_ptr<Model> make_standard_surface(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> standard_surface_options();
std::unique_ptr<Model> make_enterprise_pbr(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> enterprise_pbr_options();
std::unique_ptr<Model> make_filament(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> filament_options();
std::unique_ptr<Model> make_gltf_clearcoat(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> gltf_clearcoat_options();
std::unique_ptr<Model> make_blender_principled(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> blender_principled_options();
std::unique_ptr<Model> make_kulla_conty(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> kulla_conty_options();

}  // namespace lamina
