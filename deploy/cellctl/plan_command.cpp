#include "deploy/cellctl/plan_command.hpp"

#include <cstdio>
#include <fstream>
#include <unistd.h>
#include <iostream>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/plan_report.hpp"
#include "deploy/cellctl/text_table.hpp"
#include "deploy/cellctl/video.hpp"
#include "twin/description/automationml/precedence_writer.hpp"
#include "twin/planning/build_orientation.hpp"
#include "twin/planning/precedence_suggestions.hpp"
#include "twin/report/plan_json.hpp"
#include "twin/geometry/product_loader.hpp"
#include "twin/report/gltf_animation.hpp"
#include "twin/report/html_report.hpp"

namespace cellctl {

namespace {

// "  12.3 s  placed 4/15  motor" / "  12.5 s  backtrack 3: motor taken off"
void print_progress(const twin::PlanProgress& p) {
  char line[256];
  if (p.event == twin::PlanProgress::Event::placed) {
    std::snprintf(line, sizeof line, "%7.1f s  placed %zu/%zu  %s\n", p.seconds, p.placed, p.parts, p.part.c_str());
  } else {
    std::snprintf(line, sizeof line, "%7.1f s  backtrack %zu: %s taken off\n", p.seconds, p.backtracks, p.part.c_str());
  }
  std::cerr << line;
}

}  // namespace

void add_plan_command(CLI::App& app, int& exit_code) {
  struct Options {
    std::string product;
    std::string sequence = "search";
    std::string path = "linear";
    std::string json;
    std::string gltf;
    std::string report;
    std::string video;
    std::string suggest;
    std::string cell;
    std::string prefer = "feasible";
    double margin_mm = 1.0;
    double time_limit = 120;
    bool quiet = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("plan", "Plan and validate the assembly by virtual assembly");
  cmd->add_option("PRODUCT", options->product, "AutomationML file (.aml)")->required();
  cmd->add_option("--sequence", options->sequence, "Sequence planner")->check(CLI::IsMember({"paper", "search"}));
  cmd->add_option("--path", options->path, "Path planner")->check(CLI::IsMember({"linear", "ompl"}));
  cmd->add_option("--json", options->json, "Write the plan as JSON to this file");
  cmd->add_option("--gltf", options->gltf, "Write the virtual assembly as a glTF 2.0 animation (.gltf)");
  cmd->add_option("--report", options->report,
                  "Write the designer's report: one HTML file with the animated virtual assembly, steps, margins, "
                  "findings");
  cmd->add_option("--video", options->video,
                  "Render the virtual assembly as an MP4 (H.264) with captions for steps and findings (needs chromium "
                  "and ffmpeg)");
  cmd->add_option("--suggest", options->suggest,
                  "Where the links leave the order open and some orders fail or leave less margin, write the product "
                  "again to this .aml with the precedences that settle it");
  cmd->add_option("--cell", options->cell, "Plan for this cell: its gripper and whether it has fixtures (its deployment file, keys gripper: and fixtures:)");
  cmd->add_option("--prefer", options->prefer,
                  "What --sequence search looks for: the first feasible order, or the one with the largest least "
                  "insertion margin")
      ->check(CLI::IsMember({"feasible", "margin"}));
  cmd->add_option("--margin-threshold", options->margin_mm, "A step with less room than this (mm) is a finding")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--time-limit", options->time_limit,
                  "Seconds the search may take; then it ends with the plan that holds the most parts and says why "
                  "(0: no limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--quiet", options->quiet, "No progress lines (they go to a terminal's stderr: a part placed, a backtrack)");
  cmd->callback([options, &exit_code] {
    if (options->prefer == "margin" && options->sequence != "search") {
      throw CLI::ValidationError("--prefer margin", "needs --sequence search (the paper's sequence does not go back)");
    }
    twin::PlannerOptions planning;
    planning.objective = options->prefer == "margin" ? twin::Objective::margin : twin::Objective::feasible;
    planning.margin_threshold = options->margin_mm / 1000;
    planning.time_limit = options->time_limit;
    if (!options->quiet && ::isatty(STDERR_FILENO)) planning.progress = print_progress;
    if (!options->cell.empty()) {
      const CellConfig cell = read_cell_config(options->cell);
      planning.gripper = cell.gripper;
      planning.fixtures = cell.fixtures;
    }
    sim::MeshCache meshes;
    const twin::LoadedProduct as_given = twin::load_product(options->product, meshes);
    twin::require_geometry(as_given);
    auto sequence = twin::make_sequence_planner(options->sequence);
    auto path = twin::make_path_planner(options->path);
    twin::OrientedPlan oriented = twin::plan_in_build_orientation(as_given, *sequence, *path, planning);
    const twin::LoadedProduct& loaded = oriented.product;  // as it is built
    twin::Plan& plan = oriented.plan;
    std::vector<twin::PrecedenceSuggestion> suggestions;
    if (!options->suggest.empty()) suggestions = twin::suggest_precedences(loaded, plan, *sequence, *path, planning);
    print_plan(loaded.product, plan, std::cout);
    bool wrote = false;
    const auto written = [&wrote](const std::string& file) {
      std::cout << (wrote ? "" : "\n") << "wrote " << file << '\n';
      wrote = true;
    };
    if (!options->json.empty()) {
      std::ofstream out(options->json);
      out << twin::plan_json(loaded.product, plan).dump(2) << '\n';
      if (!out) throw std::runtime_error("cannot write " + options->json);
      written(options->json);
    }
    twin::AnimationOptions look;
    look.gripper = planning.gripper;
    if (!options->gltf.empty()) {
      twin::write_gltf_animation(loaded, plan, options->gltf, look);
      written(options->gltf);
    }
    twin::ReportOptions report;
    report.look = look;
    if (!options->report.empty()) {
      twin::write_html_report(loaded, plan, options->report, report);
      written(options->report);
    }
    if (!options->suggest.empty()) {
      std::vector<std::pair<twin::PartIndex, twin::PartIndex>> rules;
      for (const auto& s : suggestions) rules.emplace_back(s.before, s.after);
      twin::write_with_precedences(loaded.product, rules, options->suggest);
      written(options->suggest + " (" + std::to_string(rules.size()) + " precedence" + (rules.size() == 1 ? "" : "s") +
              " added)");
    }
    if (!options->video.empty()) {
      const VideoFacts video = write_video(twin::html_report(loaded, plan, report), options->video);
      written(options->video + " (" + std::to_string(video.frames) + " frames, " + fixed(video.seconds, 1) + " s)");
    }
    exit_code = plan.complete ? 0 : 1;
  });
}

}  // namespace cellctl
