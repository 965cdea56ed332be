#include "Commands.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <thread>

#include "Args.h"
#include "Mpi.h"
#include "TermProgress.h"
#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/pipeline/Calibrate.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/CompareSession.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/Inspect.h"
#include "parcelscope/pipeline/Shards.h"
#include "parcelscope/pipeline/StatsJob.h"
#include "parcelscope/pipeline/StreetEditor.h"
#include "parcelscope/pipeline/StreetsJob.h"
#include "parcelscope/viz/CompareFigures.h"

namespace parcelscope::cli {

namespace {
const char* kOverview =
    "parcelscope: observed and procedural parcels, measured side by side\n"
    "\n"
    "usage: parcelscope COMMAND [options]\n"
    "\n"
    "commands:\n"
    "  stats     read observed parcels, build blocks, write per-parcel metrics,\n"
    "            per-block statistics and generator parameters\n"
    "  blocks    build the road graph of street centre lines and its blocks\n"
    "  generate  subdivide blocks into procedural parcels (obb, skeleton, offset, parish,\n"
    "            sexton, template, access or auto style)\n"
    "  compare   generate parcels in the blocks of observed ones and compare the two sets:\n"
    "            per-block and city-wide tables, distances, layers and figures\n"
    "  calibrate give each block the style closest to its observed parcels (a session file)\n"
    "  edit      edit a street network (JSON list of edits); parcels follow, keeping their keys\n"
    "  merge     merge the shards of 'compare --shard I/N' into the outputs of one run\n"
    "  inspect   print one observed parcel's attributes, metrics and block statistics\n"
    "  metrics   print the table of parcel metrics (Markdown, as in docs/user/metrics.md)\n"
    "  version   print the version\n"
    "\n"
    "'parcelscope COMMAND --help' describes a command's options.\n";

std::vector<FlagSpec> inputFlags() {
  return {{"layer", "layer to read (default: the first)"},
          {"where", "OGR SQL attribute filter, e.g. \"ML <> 'ROAD'\""},
          {"crs", "CRS of the input (e.g. EPSG:2286), replacing a missing or wrong one"},
          {"key-field",
           "field whose value is each feature's stable key (parcel_key, block_key); default: the "
           "features' geometries"}};
}

// The street layer's flags; `prefix` is "streets-" where the layer is not the
// command's INPUT (generate, compare).
std::vector<FlagSpec> streetFlags(const std::string& prefix) {
  std::vector<FlagSpec> f;
  if (!prefix.empty()) {
    f.push_back({"streets",
                 "street centre lines (any line layer GDAL reads): blocks come from the street network\n"
                 "      and observed parcels are assigned to the block they overlap most"});
    f.push_back({prefix + "layer", "layer of the street file to read (default: the first)"});
    f.push_back({prefix + "where", "OGR SQL attribute filter on the street lines"});
  }
  f.push_back({"width-field", "street width field (metres, or the unit of a projected CRS: feet for EPSG:2286)"});
  f.push_back({"class-field", "street class field, with --class-widths"});
  f.push_back({"class-widths", "width in metres of each class value, e.g. \"1=20,2=15,residential=10\""});
  f.push_back({"name-field", "street name field"});
  f.push_back({"no-node-where",
               "OGR SQL filter selecting the lines that meet nothing they cross (bridges, tunnels),\n"
               "      e.g. \"BRIDGE = 'Y'\""});
  return f;
}

// The street read options of `a`: the path and layer flags named with `prefix`.
io::StreetReadOptions streetOptions(const Args& a, const std::string& path, const std::string& prefix) {
  io::StreetReadOptions o;
  o.path = path;
  o.layer = a.value(prefix + "layer").value_or("");
  o.where = a.value(prefix + "where").value_or("");
  if (prefix.empty()) o.crsOverride = a.value("crs").value_or("");
  o.widthField = a.value("width-field").value_or("");
  o.classField = a.value("class-field").value_or("");
  o.nameField = a.value("name-field").value_or("");
  o.noNodeWhere = a.value("no-node-where").value_or("");
  if (const auto widths = a.value("class-widths")) {
    auto trimmed = [](const std::string& t) {
      const std::size_t first = t.find_first_not_of(" \t");
      return first == std::string::npos ? std::string() : t.substr(first, t.find_last_not_of(" \t") - first + 1);
    };
    std::size_t at = 0;
    while (at <= widths->size()) {
      const std::size_t comma = std::min(widths->find(',', at), widths->size());
      const std::string item = widths->substr(at, comma - at);
      const std::size_t eq = item.rfind('=');
      const std::string name = eq == std::string::npos ? std::string() : trimmed(item.substr(0, eq));
      const std::string number = eq == std::string::npos ? std::string() : trimmed(item.substr(eq + 1));
      double w = NAN;
      std::size_t used = 0;
      try {
        if (!number.empty() && !readsAsNonDecimalNumber(number)) w = std::stod(number, &used);
      } catch (const std::exception&) {
      }
      if (name.empty() || used != number.size() || !std::isfinite(w) || w < 0 || w > io::kMaxStreetWidth) {
        throw usageError("--class-widths: '" + item + "' is not CLASS=METRES (a decimal width of 0 to " +
                         std::to_string(static_cast<int>(io::kMaxStreetWidth)) + " m)");
      }
      if (!o.classWidths.emplace(name, w).second) {
        throw usageError("--class-widths: class '" + name + "' is given twice");
      }
      at = comma + 1;
    }
    if (o.classField.empty()) throw usageError("--class-widths needs --class-field");
  }
  return o;
}

// --streets and its flags, when given.
std::optional<io::StreetReadOptions> streetsOf(const Args& a) {
  const auto path = a.value("streets");
  if (!path) {
    for (const char* flag : {"streets-layer", "streets-where", "width-field", "class-field", "class-widths",
                             "name-field", "no-node-where"}) {
      if (a.has(flag)) throw usageError(std::string("--") + flag + " needs --streets");
    }
    return std::nullopt;
  }
  return streetOptions(a, *path, "streets-");
}

template <typename T>
std::vector<T> joined(std::vector<T> a, const std::vector<T>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// The flags of a STREETS input (blocks, edit).
std::vector<FlagSpec> streetInputFlags() {
  return joined<FlagSpec>({{"layer", "layer of STREETS to read (default: the first)"},
                           {"where", "OGR SQL attribute filter on the street lines"},
                           {"crs", "CRS of STREETS (e.g. EPSG:2286), replacing a missing or wrong one"}},
                          streetFlags(""));
}

FlagSpec styleFlag() {
  std::string help = "subdivision style (default obb):";
  for (const auto& [name, text] : generation::generationStyles()) help += "\n      " + name + ": " + text;
  return {"style", help};
}

bool wantsHelp(const std::vector<std::string>& args) {
  for (const auto& a : args) {
    if (a == "--help" || a == "-h") return true;
  }
  return false;
}

// Names of the parameters the user gave (as opposed to their defaults).
std::set<std::string> givenParameters(const Args& a, const std::vector<ParameterDescription>& params) {
  std::set<std::string> given;
  for (const auto& p : params) {
    if (a.given(p.name)) given.insert(p.name);
  }
  return given;
}

// Prints a finished job's summary (unless --quiet) and returns the exit code.
int reportOutcome(const pipeline::JobOutcome& outcome, const Args& a) {
  if (!a.has("quiet")) std::fprintf(stderr, "%s\nwritten to %s\n", outcome.summary.c_str(), a.value("out")->c_str());
  // The program exits next: the job's result (millions of small allocations
  // on a large input, 0.4 s to free) goes back to the system with the process.
  static auto* const kept = new std::vector<std::shared_ptr<const void>>;
  if (outcome.result) kept->push_back(outcome.result);
  return 0;
}

// The one INPUT and the input flags of inputFlags(); --out is required.
io::ReadOptions readOptions(const Args& a) {
  if (a.positional().size() != 1) throw usageError("expected exactly one INPUT file");
  if (!a.value("out")) throw usageError("--out DIR is required");
  io::ReadOptions input;
  input.path = a.positional()[0];
  input.layer = a.value("layer").value_or("");
  input.where = a.value("where").value_or("");
  input.crsOverride = a.value("crs").value_or("");
  input.keyField = a.value("key-field").value_or("");
  return input;
}
}  // namespace

int dispatch(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::fputs(kOverview, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (args[0] == "version" || args[0] == "--version") {
    if (rest.size() == 1 && (rest[0] == "--help" || rest[0] == "-h")) {
      std::puts("parcelscope version: prints the version of ParcelScope (no arguments)");
      return 0;
    }
    if (!rest.empty()) throw usageError("version takes no arguments ('" + rest.front() + "' given)");
    std::printf("parcelscope %s\n", pipeline::version().c_str());
    return 0;
  }
  // Under mpirun every rank runs the command line: only compare splits its work.
  if (mpiSize() > 1 && args[0] != "compare") {
    throw usageError("'" + args[0] + "' runs in one process; under mpirun only 'compare' runs in ranks");
  }
  if (args[0] == "metrics") return metricsCommand(rest);
  if (args[0] == "stats") return statsCommand(rest);
  if (args[0] == "blocks") return blocksCommand(rest);
  if (args[0] == "generate") return generateCommand(rest);
  if (args[0] == "compare") return compareCommand(rest);
  if (args[0] == "inspect") return inspectCommand(rest);
  if (args[0] == "calibrate") return calibrateCommand(rest);
  if (args[0] == "edit") return editCommand(rest);
  if (args[0] == "merge") return mergeCommand(rest);
  throw usageError("unknown command '" + args[0] +
                   "' (commands: stats, blocks, generate, compare, calibrate, edit, merge, inspect, metrics, version)");
}

int metricsCommand(const std::vector<std::string>& args) {
  if (wantsHelp(args)) {
    std::fputs(
        "usage: parcelscope metrics\n\nPrints every parcel metric (name, unit, formula, range, source) as a\n"
        "Markdown table: the table of docs/user/metrics.md, made from the metric registry.\n",
        stdout);
    return 0;
  }
  if (!args.empty()) throw usageError("metrics takes no arguments");
  // A vertical bar inside a cell is escaped, so the table stays a table.
  auto cell = [](std::string text) {
    if (text.empty()) return std::string("-");
    for (std::size_t i = text.find('|'); i != std::string::npos; i = text.find('|', i + 2)) text.insert(i, "\\");
    return text;
  };
  std::printf("| metric | unit | formula | range | source |\n|---|---|---|---|---|\n");
  for (const auto& q : analysis::parcelMetrics()) {
    const std::string formula = q.formula + (q.context ? "; measured against the parcel's surroundings" : "");
    std::printf("| `%s` | %s | %s | %s | %s |\n", q.name.c_str(), cell(q.unit).c_str(), cell(formula).c_str(),
                cell(q.range).c_str(), cell(q.source).c_str());
  }
  return 0;
}

int statsCommand(const std::vector<std::string>& args) {
  auto flags = inputFlags();
  flags.push_back({"out", "output directory (created; files appear only when the run succeeds)"});
  flags.push_back({"quiet", "no progress or summary on stderr", false});
  const auto& params = analysis::analysisParameters();
  if (wantsHelp(args)) {
    std::fputs(usageText("parcelscope stats INPUT [options] --out DIR", flags, params).c_str(), stdout);
    std::fputs("\nwrites DIR/parcels.csv, DIR/blocks.csv, DIR/blocks.gpkg and DIR/run.json\n", stdout);
    return 0;
  }
  const Args a(args, flags, params);
  return reportOutcome(
      pipeline::runStats(readOptions(a), a.parameters(), *a.value("out"), terminalProgress(a.has("quiet"))), a);
}

int blocksCommand(const std::vector<std::string>& args) {
  std::vector<FlagSpec> flags = streetInputFlags();
  flags.push_back({"parcels",
                   "observed parcels: unknown widths are measured from the gap between their blocks,\n"
                   "      and blocks.gpkg counts each block's parcels"});
  flags.push_back({"parcels-where", "OGR SQL attribute filter on the parcels, e.g. \"ML <> 'ROAD'\""});
  flags.push_back({"out", "output directory (created; files appear only when the run succeeds)"});
  flags.push_back({"quiet", "no progress or summary on stderr", false});
  const auto params = joined(pipeline::streetParameters(), analysis::analysisParameters());
  if (wantsHelp(args)) {
    std::fputs(
        usageText("parcelscope blocks STREETS [--width-field F] [--default-width M] [--street-snap M] [--where SQL] "
                  "[--parcels PARCELS] --out DIR",
                  flags, params)
            .c_str(),
        stdout);
    std::fputs(
        "\nBuilds the planar road graph of the street centre lines and its blocks (faces minus the\n"
        "street surface). Writes DIR/blocks.gpkg (layer blocks), DIR/streets.gpkg (layers nodes and\n"
        "edges), DIR/street_surface.gpkg and DIR/run.json.\n",
        stdout);
    return 0;
  }
  const Args a(args, flags, params);
  if (a.positional().size() != 1) throw usageError("expected exactly one STREETS file");
  if (!a.value("out")) throw usageError("--out DIR is required");
  const io::StreetReadOptions streets = streetOptions(a, a.positional()[0], "");
  std::optional<io::ReadOptions> parcels;
  if (const auto path = a.value("parcels")) {
    parcels.emplace();
    parcels->path = *path;
    parcels->where = a.value("parcels-where").value_or("");
  } else if (a.has("parcels-where")) {
    throw usageError("--parcels-where needs --parcels");
  }
  return reportOutcome(pipeline::runBlocks(streets, a.parameters(), parcels ? &*parcels : nullptr, *a.value("out"),
                                           terminalProgress(a.has("quiet"))),
                       a);
}

namespace {

// Whether `path` is a session file (its first kilobytes name parcelscope_session).
bool isSessionFile(const std::string& path) {
  std::ifstream in(path);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head.find("\"parcelscope_session\"") != std::string::npos;
}

}  // namespace

int editCommand(const std::vector<std::string>& args) {
  std::vector<FlagSpec> flags = streetInputFlags();
  flags.push_back(styleFlag());
  flags.push_back({"edits", "JSON list of edits to apply in order (docs/user/cli.md#parcelscope-edit)"});
  flags.push_back({"out", "output directory (created; files appear only when the run succeeds)"});
  flags.push_back({"quiet", "no progress or summary on stderr", false});
  const std::vector<ParameterDescription> params =
      joined(generation::generationParameterDescriptions(), pipeline::streetParameters());
  if (wantsHelp(args)) {
    std::fputs(
        usageText("parcelscope edit STREETS|SESSION [--style S] [--seed N] --edits EDITS.json --out DIR", flags, params)
            .c_str(),
        stdout);
    std::fputs(
        "\nBuilds the street network of STREETS and subdivides its blocks (as 'generate --streets'),\n"
        "then applies the edits of EDITS.json in order: move_node, move_edge, set_width, set_curve,\n"
        "transform_nodes, insert_node, add_street, delete_street, set_block, set_label, set_lock.\n"
        "Only the blocks an edit changes are subdivided again; their parcels are matched to those\n"
        "before, and a matched parcel keeps its key. Writes DIR/parcels.gpkg (with parcel_key,\n"
        "label and locked), DIR/blocks.gpkg, DIR/streets.gpkg,\n"
        "DIR/street_surface.gpkg, DIR/persistence.csv (per edit: blocks affected, parcels before\n"
        "and after, keys kept) and DIR/run.json. A SESSION (of 'compare --streets', or saved by the\n"
        "application) edits the network it compares: its observed parcels give each block its bounds\n"
        "and the first parcels are those 'compare' generates, as in the application's Edit > Edit streets.\n",
        stdout);
    return 0;
  }
  const Args a(args, flags, params);
  if (a.positional().size() != 1) throw usageError("expected exactly one STREETS file");
  if (!a.value("out")) throw usageError("--out DIR is required");
  if (!a.value("edits")) throw usageError("--edits EDITS.json is required");
  pipeline::GenerateRequest request;
  const std::string& input = a.positional()[0];
  request.style = a.value("style").value_or("obb");
  request.parameters = a.parameters();
  request.explicitParameters = givenParameters(a, params);
  if (isSessionFile(input)) {
    // A session of `compare --streets`: the network it compares, with its
    // observed parcels' per-block bounds, style, parameters and overrides (as
    // the application edits it); flags given here override the session's.
    pipeline::CompareRequest session = pipeline::readSession(input);
    if (!session.streets) throw inputError(input + ": the session has no streets to edit");
    if (session.input.path == session.streets->path) {
      // A session naming its streets as its input has no observed parcels: the network alone.
      request.streets = session.streets;
      request.style = session.style;
      for (const auto& [name, value] : session.parameters) request.parameters[name] = value;
      request.explicitParameters.insert(session.explicitParameters.begin(), session.explicitParameters.end());
      request.overrides = session.overrides;
      return reportOutcome(
          pipeline::runEdit(request, *a.value("edits"), *a.value("out"), terminalProgress(a.has("quiet"))), a);
    }
    if (a.value("style")) session.style = *a.value("style");
    for (const std::string& name : givenParameters(a, params)) {
      session.parameters[name] = request.parameters.at(name);
      session.explicitParameters.insert(name);
    }
    return reportOutcome(
        pipeline::runEdit(session, *a.value("edits"), *a.value("out"), terminalProgress(a.has("quiet"))), a);
  } else {
    request.streets = streetOptions(a, input, "");
  }
  return reportOutcome(pipeline::runEdit(request, *a.value("edits"), *a.value("out"), terminalProgress(a.has("quiet"))),
                       a);
}

int generateCommand(const std::vector<std::string>& args) {
  auto flags = inputFlags();
  flags.push_back(styleFlag());
  flags.push_back(
      {"from-parcels", "INPUT holds observed parcels: build blocks and per-block bounds as 'stats' does", false});
  flags = joined(flags, streetFlags("streets-"));
  flags.push_back({"out", "output directory (created; files appear only when the run succeeds)"});
  flags.push_back({"quiet", "no progress or summary on stderr", false});
  const std::vector<ParameterDescription> params =
      joined(generation::generationParameterDescriptions(), pipeline::streetParameters());
  if (wantsHelp(args)) {
    std::fputs(
        usageText("parcelscope generate INPUT [--style STYLE] [options] [--seed N] --out DIR", flags, params).c_str(),
        stdout);
    std::fputs(
        "\nINPUT holds block polygons (e.g. blocks.gpkg from 'parcelscope stats', whose a_min, a_max,\n"
        "w_min and w_max fields are used per block unless given here), or observed parcels with\n"
        "--from-parcels. With --streets STREETS, blocks are the street network's (as 'parcelscope\n"
        "blocks' builds them); INPUT, optional, then holds observed parcels, assigned to the street\n"
        "block they overlap most for per-block bounds. Writes DIR/parcels.gpkg, DIR/parcels.csv and\n"
        "DIR/run.json.\n",
        stdout);
    return 0;
  }
  const Args a(args, flags, params);
  pipeline::GenerateRequest request;
  request.streets = streetsOf(a);
  if (request.streets && a.positional().empty()) {
    // Blocks from the streets alone: the run's values for every block.
    if (!a.value("out")) throw usageError("--out DIR is required");
    if (a.has("from-parcels")) throw usageError("--from-parcels needs an INPUT of observed parcels");
  } else {
    request.input = readOptions(a);
    request.fromParcels = a.has("from-parcels") || request.streets.has_value();
  }
  request.style = a.value("style").value_or("obb");
  request.parameters = a.parameters();
  request.explicitParameters = givenParameters(a, params);
  return reportOutcome(pipeline::runGenerate(request, *a.value("out"), terminalProgress(a.has("quiet"))), a);
}

namespace {
// `compare` under mpirun: each rank one shard, rank 0 merges and writes.
int compareOnRanks(const pipeline::CompareRequest& request, const std::string& out, const Args& a);
}  // namespace

int compareCommand(const std::vector<std::string>& args) {
  auto flags = inputFlags();
  flags.push_back(styleFlag());
  flags.back().help += "\n      all: every style on the same blocks, a leaderboard (leaderboard.csv, ...)";
  {
    std::string help = "parcel quantity of the extra figures map_METRIC and hist_METRIC (default aspect_ratio):";
    for (const auto& q : analysis::parcelQuantities()) help += "\n      " + q.name + ": " + q.title;
    flags.push_back({"metric", help});
  }
  flags.push_back({"vector", "format of the histograms' vector copy: svg (default) or pdf"});
  flags.push_back({"parcels-format", "generated parcels as gpkg (parcels.gpkg, default) or geojson (parcels.geojson)"});
  flags.push_back({"session",
                   "session file (saved by parcelscope-gui, or a compare run.json): input, style,\n"
                   "      parameters, per-block overrides (the only way to give those here) and seed;\n"
                   "      INPUT and options given here win"});
  flags = joined(flags, streetFlags("streets-"));
  flags.push_back({"shard",
                   "I/N: analyse only shard I (0 to N-1) of N vertical strips of INPUT and write it\n"
                   "      to --out (shard.bin); 'parcelscope merge' of the N folders writes the run"});
  flags.push_back({"out", "output directory (created; files appear only when the run succeeds)"});
  flags.push_back({"quiet", "no progress or summary on stderr", false});
  const auto params = joined(pipeline::compareParameters(), pipeline::streetParameters());
  if (wantsHelp(args)) {
    std::fputs(usageText("parcelscope compare INPUT|--session FILE [--style STYLE] [--k 2] [--seed "
                         "N] [options] --out DIR",
                         flags, params)
                   .c_str(),
               stdout);
    std::fputs(
        "\nINPUT holds observed parcels. They are grouped into blocks and measured as 'stats' does; every\n"
        "block is subdivided with its own bounds (A-bar -/+ k s_A, W-bar -/+ k s_W) unless --a-min etc.\n"
        "are given; both sets are measured alike and compared. Writes DIR/parcels.gpkg, blocks.gpkg,\n"
        "observed_parcels.csv, generated_parcels.csv, blocks.csv, summary.csv, distances.csv,\n"
        "summary.json, run.json and DIR/figures/*.png and *.svg or *.pdf (figures need an X server: use\n"
        "'xvfb-run -a' without a screen, or --figures no).\n"
        "\nUnder 'mpirun -n N', the N ranks each read and analyse one vertical strip of INPUT (a\n"
        "GeoPackage through its R-tree) and rank 0 writes the outputs one process writes (run.json\n"
        "adds \"ranks\").\n",
        stdout);
    return 0;
  }
  const Args a(args, flags, params);
  pipeline::CompareRequest request;
  if (const auto session = a.value("session")) {
    // The session's request, with what the command line gives on top.
    request = pipeline::readSession(*session);
    if (!a.value("out")) throw usageError("--out DIR is required");
    if (a.positional().size() > 1) throw usageError("expected at most one INPUT file");
    if (a.positional().size() == 1) request.input.path = a.positional()[0];
    if (auto v = a.value("layer")) request.input.layer = *v;
    if (auto v = a.value("where")) request.input.where = *v;
    if (auto v = a.value("crs")) request.input.crsOverride = *v;
    if (auto v = a.value("key-field")) request.input.keyField = *v;
    const ParameterValues values = a.parameters();
    for (const auto& name : givenParameters(a, params)) {
      request.parameters[name] = values.at(name);
      request.explicitParameters.insert(name);
    }
  } else {
    request.input = readOptions(a);
    request.parameters = a.parameters();
    request.explicitParameters = givenParameters(a, params);
  }
  if (auto streets = streetsOf(a)) request.streets = std::move(streets);
  if (auto v = a.value("style")) request.style = *v;
  if (auto v = a.value("metric")) request.metric = *v;
  if (auto v = a.value("vector")) request.vectorFormat = *v;
  if (auto v = a.value("parcels-format")) request.parcelsFormat = *v;
  if (const auto shard = a.value("shard")) {
    if (mpiSize() > 1) throw usageError("--shard runs one shard in one process; under mpirun, leave it out");
    const auto [index, count] = pipeline::parseShard(*shard);
    if (request.style == "all") throw usageError("--shard: runs one style (not --style all)");
    return reportOutcome(pipeline::runShard(request, index, count, *a.value("out"), terminalProgress(a.has("quiet"))),
                         a);
  }
  if (mpiSize() > 1) {
    if (request.style == "all") throw usageError("mpirun: compare runs one style (not --style all)");
    return compareOnRanks(request, *a.value("out"), a);
  }
  if (request.style == "all") {
    return reportOutcome(viz::runLeaderboard(request, *a.value("out"), terminalProgress(a.has("quiet"))), a);
  }
  return reportOutcome(viz::runCompare(request, *a.value("out"), terminalProgress(a.has("quiet"))), a);
}

namespace {
int compareOnRanks(const pipeline::CompareRequest& request, const std::string& out, const Args& a) {
  const int rank = mpiRank(), size = mpiSize();
  const std::string who = "parcelscope compare (rank " + std::to_string(rank) + " of " + std::to_string(size) + ")";
  if (rank == 0 && workerCount() < std::thread::hardware_concurrency() && !a.has("quiet")) {
    std::fprintf(stderr,
                 "parcelscope compare: rank 0 may use %u of this machine's %u cores, and alone merges and "
                 "writes; 'mpirun --bind-to none' (or more cores per rank) lets it use more\n",
                 workerCount(), std::thread::hardware_concurrency());
  }
  // Rank 0 keeps its own part as it is and decodes each other rank's as it
  // arrives; the others send theirs and are done.
  std::vector<pipeline::ShardPart> decoded;
  try {
    const ProgressFn progress = rank == 0 ? terminalProgress(a.has("quiet")) : ProgressFn{};
    pipeline::ShardPart part =
        pipeline::analyseShard(request, rank, size, rankReading(), scaledProgress(progress, 0.0, 0.5));
    if (rank != 0) {
      const std::string bytes = pipeline::encodeShard(part);
      part = pipeline::ShardPart{};
      sendPart(bytes);
      return 0;
    }
    decoded.push_back(std::move(part));
    receiveParts([&](int r, std::string bytes) {
      decoded.push_back(pipeline::decodeShard(bytes, "rank " + std::to_string(r)));
    });
  } catch (const std::exception& e) {
    abortRanks(who + ": " + e.what() + "; every rank stopped, nothing was written");
  }
  const pipeline::PreparedObserved prepared = pipeline::prepareMerged(std::move(decoded), size, request.input);
  return reportOutcome(viz::runCompare(request, out, terminalProgress(a.has("quiet")), &prepared), a);
}
}  // namespace

int mergeCommand(const std::vector<std::string>& args) {
  const std::vector<FlagSpec> flags = {{"out", "output directory (created; files appear only when the merge succeeds)"},
                                       {"quiet", "no progress or summary on stderr", false}};
  if (wantsHelp(args)) {
    std::fputs(usageText("parcelscope merge SHARD_DIR... --out DIR", flags, {}).c_str(), stdout);
    std::fputs(
        "\nMerges the folders written by 'parcelscope compare ... --shard I/N --out SHARD_DIR' for every I\n"
        "of N (array jobs of a scheduler without MPI): the observed blocks of the shards are joined as\n"
        "one process reads them, then parcels are generated and compared and DIR receives what\n"
        "'compare' without --shard writes (run.json adds \"ranks\" and \"shards\").\n",
        stdout);
    return 0;
  }
  const Args a(args, flags, {});
  if (!a.value("out")) throw usageError("--out DIR is required");
  auto [request, prepared] = pipeline::readShards(a.positional());
  return reportOutcome(viz::runCompare(request, *a.value("out"), terminalProgress(a.has("quiet")), &prepared), a);
}

int calibrateCommand(const std::vector<std::string>& args) {
  auto flags = joined(inputFlags(), streetFlags("streets-"));
  flags.push_back({"out", "output directory (created; files appear only when the run succeeds)"});
  flags.push_back({"quiet", "no progress or summary on stderr", false});
  const auto params = joined(pipeline::compareParameters(), pipeline::streetParameters());
  if (wantsHelp(args)) {
    std::fputs(usageText("parcelscope calibrate INPUT [--k 2] [--seed N] [options] --out DIR", flags, params).c_str(),
               stdout);
    std::fputs(
        "\nRuns every style on INPUT's blocks (as 'compare --style all') and gives each block the style\n"
        "whose parcels come closest to its observed ones: KS area + KS width + KS aspect ratio +\n"
        "|n_generated / n_observed - 1|. Writes DIR/session.json (for 'compare --session' and the\n"
        "application), calibration.csv (per block: style and distance before and after, the\n"
        "cross-validated choice), leaderboard.csv and run.json (city-wide measures before, after and\n"
        "cross-validated: a rule fitted on half of the blocks, measured on the other half).\n",
        stdout);
    return 0;
  }
  const Args a(args, flags, params);
  pipeline::CompareRequest request;
  request.input = readOptions(a);
  request.parameters = a.parameters();
  request.explicitParameters = givenParameters(a, params);
  request.style = "auto";
  if (auto streets = streetsOf(a)) request.streets = std::move(streets);
  return reportOutcome(viz::runCalibrate(request, *a.value("out"), terminalProgress(a.has("quiet"))), a);
}

int inspectCommand(const std::vector<std::string>& args) {
  auto flags = inputFlags();
  flags.push_back({"at",
                   "the point X,Y in the input's coordinates: LON,LAT for a geographic CRS, else the\n"
                   "      projected CRS's easting and northing (that of --crs when given)"});
  flags.push_back({"json", "print JSON instead of 'name: value' lines", false});
  const auto& params = analysis::analysisParameters();
  if (wantsHelp(args)) {
    std::fputs(usageText("parcelscope inspect INPUT --at X,Y [--json] [options]", flags, params).c_str(), stdout);
    std::fputs(
        "\nReads and measures INPUT as 'stats' does and prints the parcel at the point: its ids and\n"
        "key, every parcel metric and its block's statistics (block.*), one 'name: value' per line.\n",
        stdout);
    return 0;
  }
  const Args a(args, flags, params);
  if (a.positional().size() != 1) throw usageError("expected exactly one INPUT file");
  const auto at = a.value("at");
  if (!at) throw usageError("--at X,Y is required");
  pipeline::InspectRequest request;
  {
    const std::size_t comma = at->find(',');
    std::size_t xEnd = 0, yEnd = 0;
    bool ok = comma != std::string::npos;
    try {
      if (ok) request.x = std::stod(at->substr(0, comma), &xEnd);
      if (ok) request.y = std::stod(at->substr(comma + 1), &yEnd);
    } catch (const std::exception&) {
      ok = false;
    }
    ok = ok && xEnd == comma && yEnd == at->size() - comma - 1 && std::isfinite(request.x) && std::isfinite(request.y);
    if (!ok) throw usageError("--at " + *at + " is not X,Y (two decimal numbers separated by a comma)");
  }
  request.input.path = a.positional()[0];
  request.input.layer = a.value("layer").value_or("");
  request.input.where = a.value("where").value_or("");
  request.input.crsOverride = a.value("crs").value_or("");
  request.input.keyField = a.value("key-field").value_or("");
  request.parameters = a.parameters();
  const pipeline::ParcelInspection inspection = pipeline::inspect(request);
  const std::string text =
      a.has("json") ? pipeline::inspectionJson(inspection).dump() + "\n" : pipeline::inspectionText(inspection);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace parcelscope::cli
