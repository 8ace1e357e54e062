// `cheval res FILE... [--label NAME]... [--save-table FILE] [--table-format F]`: evo_res's statistics
// table of result files (evo's zips, cheval's --save-results zips, cheval's --json output), printed as
// evo_res prints it and written as Markdown, LaTeX or CSV (docs/cli.md, "cheval res").
#include <filesystem>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/eval/res_read.h"
#include "cheval/eval/res_table.h"
#include "common.h"

namespace cheval::cli {
namespace {

struct ResFlags {
  std::vector<std::string> files, labels;
  std::string save_table, table_format;
  bool use_filenames = false, ignore_title = false;
};

// The table in `format` (markdown, latex or csv; as CLI11 checked it).
std::string Render(const eval::ResTable& t, const std::string& format) {
  if (format == "markdown") return eval::ResTableMarkdown(t);
  if (format == "latex") return eval::ResTableLatex(t);
  return eval::ResTableCsv(t);
}

// --save-table's format: --table-format, else the file's extension, else CSV (evo's table_export_format).
std::string SaveFormat(const ResFlags& flags) {
  if (!flags.table_format.empty()) return flags.table_format;
  const std::string ext = std::filesystem::path(flags.save_table).extension().string();
  if (ext == ".md" || ext == ".markdown") return "markdown";
  if (ext == ".tex") return "latex";
  return "csv";
}

void Run(const ResFlags& flags) {
  RefuseSharedPaths(flags.files, {{"--save-table", flags.save_table}});
  std::vector<eval::ResultFile> results;
  for (const std::string& file : flags.files) {
    for (eval::ResultFile& r : eval::ReadResultFile(file)) results.push_back(std::move(r));
  }
  eval::ResTableOptions options;
  options.labels = flags.labels;
  options.use_filenames = flags.use_filenames;
  const eval::ResTable table = eval::BuildResTable(results, options);
  if (!flags.ignore_title) {
    for (const std::string& conflict : table.title_conflicts) {
      fmt::print(stderr, "cheval: warning: the title differs from the first file's ({}): {}; the first is used "
                         "(--ignore-title leaves titles out)\n", flags.files.front(), conflict);
    }
  }
  std::string text;
  if (!flags.table_format.empty() && flags.save_table.empty()) {
    text = Render(table, flags.table_format);
  } else {
    // evo_res: logger.info("\n" + title + "\n\n") and logger.info(table + "\n"), each line ending.
    if (!flags.ignore_title && !table.title.empty()) text = fmt::format("\n{}\n\n\n", table.title);
    text += eval::EvoResText(table) + "\n\n";
  }
  std::vector<OutputFile> outputs = {{"-", text}};
  std::string saved;
  if (!flags.save_table.empty()) {
    saved = Render(table, SaveFormat(flags));
    outputs.push_back({flags.save_table, saved});
  }
  WriteOutputs(outputs);
}

}  // namespace

void RegisterRes(CLI::App& app, Action* action) {
  auto flags = std::make_shared<ResFlags>();
  CLI::App* command = app.add_subcommand(
      "res", "Print evo_res's statistics table of result files: evo's result zips, cheval's --save-results zips, "
             "cheval's --json output; write it as Markdown, LaTeX or CSV");
  command->add_option("files", flags->files, "Result files (.zip from evo or cheval --save-results, cheval --json)")
      ->required();
  command->add_option("--label", flags->labels,
                      "Name of each result in the table (repeat, in order; default: the base name of its est_name)");
  command->add_flag(FlagNames("--use-filenames"), flags->use_filenames,
                    "Name each result by its file's path (evo_res --use_filenames)");
  command->add_flag(FlagNames("--ignore-title"), flags->ignore_title,
                    "Print no title and do not warn when the results' titles differ");
  command->add_option(FlagNames("--save-table"), flags->save_table,
                      "Write the table to FILE (format: --table-format, else by extension .md/.tex/.csv, else CSV)");
  command->add_option("--table-format", flags->table_format,
                      "markdown, latex or csv: the format of --save-table, or of standard output without it")
      ->transform(CLI::IsMember({"markdown", "latex", "csv"}));
  command->callback([flags, action] { *action = [flags] { Run(*flags); }; });
}

}  // namespace cheval::cli
