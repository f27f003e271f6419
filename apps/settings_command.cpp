// `nimbus settings`: the render settings of the scene format (render/settings.h).

#include <cstdio>
#include <memory>
#include <string>

#include "command.h"
#include "nimbus/render/settings.h"

namespace {

// `nimbus settings`: every render setting (render/settings.h), or one section's Markdown table.
int list_settings(const std::string& markdown_section) {
  using namespace nimbus;
  if (!markdown_section.empty()) {
    std::fputs(settings_markdown(markdown_section).c_str(), stdout);
    return 0;
  }
  const RenderSettings defaults;
  for (const Setting& s : render_settings())
    std::printf("%-28s %-18s %s\n", std::string(s.key).c_str(), s.get(defaults).dump().c_str(),
                std::string(s.doc).c_str());
  return 0;
}

}  // namespace

Command settings_command(CLI::App& app) {
  const auto markdown_section = std::make_shared<std::string>();
  CLI::App* settings = app.add_subcommand(
      "settings", "List the render settings of the scene format: key, type, default, meaning");
  settings
      ->add_option("--markdown", *markdown_section,
                   "Print the Markdown table of one section (film, integrator, spectrum), as "
                   "docs/scene-format.md holds it")
      ->check(CLI::IsMember({"film", "integrator", "spectrum"}));
  return {settings,
          [markdown_section](const Cluster&) { return list_settings(*markdown_section); }};
}
