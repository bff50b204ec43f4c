#pragma once
// The registry's entry points of the production coats (production_coats.cpp: each coat's recipe
// for the one engine of models/production/production_coat.h, and its flags).

#include "models/model.h"

#include <memory>
#include <vector>

namespace lamina {

std::unique_ptr<Model> make_openpbr(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> openpbr_options();
std::unique_ptr<Model> make_openpbr_adobe(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> openpbr_adobe_options();
std::unique_ptr<Model> make_standard_surface(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> standard_surface_options();
std::unique_ptr<Model> make_standard_surface_materialx(const Stack& stack,
                                                       const ModelOptions& options);
std::vector<OptionSpec> standard_surface_materialx_options();
std::unique_ptr<Model> make_enterprise_pbr(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> enterprise_pbr_options();
std::unique_ptr<Model> make_filament(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> filament_options();
std::unique_ptr<Model> make_gltf_clearcoat(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> gltf_clearcoat_options();
std::unique_ptr<Model> make_blender_principled(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> blender_principled_options();
std::unique_ptr<Model> make_threejs_clearcoat(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> threejs_clearcoat_options();
std::unique_ptr<Model> make_openpbr_materialx(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> openpbr_materialx_options();
std::unique_ptr<Model> make_kulla_conty(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> kulla_conty_options();

}  // namespace lamina
