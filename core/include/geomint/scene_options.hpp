#pragma once
// The parameters of a scene as options of a program that runs it directly (not through --system): every parameter
// the scene visits (name, value, description) becomes --name with the scene's value as its default, so such a
// program takes the same parameters under the same names as the programs that take --system.
#include <initializer_list>
#include <string_view>

#include "geomint/cli.hpp"

namespace geomint {

// `except`: the parameters the program sets itself (a list it sweeps, such as alpha, or a horizon it takes as a list).
template <class Scene>
void add_scene_options(Cli& cli, Scene& scene, std::initializer_list<std::string_view> except) {
  scene.visit([&](const char* name, double& value, const char* what) {
    for (std::string_view e : except)
      if (e == name) return;
    cli.options.add_options()(name, po::value(&value)->default_value(value), what);
  });
}

}  // namespace geomint
