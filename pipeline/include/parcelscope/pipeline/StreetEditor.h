#pragma once
// Editing a street network with its procedural parcels kept up to date
// (Vanegas et al. 2012, sections 3.2 and 5): an edit changes the road graph or
// a block's style or parameters; the blocks are the graph's faces again, and
// only the blocks whose contour, faced streets or plan changed are subdivided
// again. Nodes, edges and blocks keep their keys across geometric edits (a
// moved node is the same node); an edit of the topology (a street added,
// deleted, a node inserted) nodes the streets again, and what it did not
// change keeps its key. A regenerated block's parcels are matched to
// its parcels before the edit (generation::matchParcels): a matched parcel
// keeps its key and its label. Every edit can be undone and redone, bit for
// bit. No Qt: the application and `parcelscope edit` drive the same class.
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "parcelscope/core/Json.h"
#include "parcelscope/core/Table.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/StreetsJob.h"

namespace parcelscope::pipeline {

/// One edit, coordinates in the editor's local metres (StreetEditor::toLocal
/// converts from the input's CRS).
struct StreetEdit {
  enum class Op {
    MoveNode,        ///< node `node` to `to`
    MoveEdge,        ///< both ends of edge `edge` (and its inner vertices and control points) by `by`
    SetWidth,        ///< edge `edge`'s width to `width` (m)
    SetCurve,        ///< edge `edge` a cubic Bezier with `controls` (none: its straight segment)
    TransformNodes,  ///< nodes `nodes` scaled by `scale` and rotated by `rotate` (deg) about `centre`, then moved by
                     ///< `by`
    SetBlock,        ///< block `block`'s style (empty: the run's) and parameters (replacing its former override)
    SetLabel,        ///< parcel `parcel`'s label to `label` (empty: none); it follows the parcel across edits
    InsertNode,      ///< a node on edge `edge` at the point of it nearest `to` (a T-junction to be)
    AddStreet,       ///< a straight street from `from` (or node `node`) to `to` (or node `node2`), `width`, `name`
    DeleteStreet,    ///< edge `edge` removed
    SetLock,         ///< parcel `parcel` locked (`locked`) or unlocked: see StreetEditor::setLock
  };
  Op op = Op::MoveNode;
  Key node = 0, node2 = 0, edge = 0, block = 0, parcel = 0;
  Point from, to, by, centre;
  double width = NAN, rotate = 0, scale = 1;
  std::optional<std::array<Point, 2>> controls;
  std::vector<Key> nodes;
  std::string style;
  ParameterValues parameters;
  std::string label;
  std::string name;  ///< a new street's name
  bool locked = true;
};

/// The name of an edit's op as the edits file spells it ("move_node", ...).
const char* editOpName(StreetEdit::Op op);

/// What one edit did.
struct EditReport {
  std::string op;
  /// Blocks subdivided again (their keys), and blocks gone (no block of the new
  /// network has their key).
  std::vector<Key> blocksAffected, blocksRemoved;
  /// Parcels of the affected blocks before and after; parcels after that were
  /// matched to a parcel before (and keep its key and label).
  std::int64_t parcelsBefore = 0, parcelsAfter = 0, matched = 0;
  /// Seconds in all, building the blocks again (the whole network's faces),
  /// subdividing the affected blocks, matching their parcels.
  double seconds = 0, secondsBlocks = 0, secondsSubdivide = 0, secondsMatch = 0;
};

class StreetEditor {
public:
  /// The network and parcels `request` describes: its `streets` (required)
  /// without observed parcels, its style, parameters and overrides. Throws as
  /// generate().
  explicit StreetEditor(const GenerateRequest& request, const ProgressFn& progress = {});
  /// The network of observed parcels grouped in the blocks of their streets
  /// (loadObservedInStreetBlocks; `observed->streets` is required), as the
  /// application compares them: the editor starts from that network (its
  /// frame, measured widths and closing boundary) with `request`'s style,
  /// parameters and overrides, and its first parcels are those `compare`
  /// generates for it. A block keeps the bounds and observed sample its
  /// observed parcels gave it for as long as it keeps its key; a block new to
  /// the network takes the run's values. `observed` is what compare() reads
  /// for `request`. Throws Error(Usage) without streets.
  StreetEditor(const CompareRequest& request, std::shared_ptr<const ObservedData> observed,
               const ProgressFn& progress = {});
  ~StreetEditor();
  StreetEditor(const StreetEditor&) = delete;
  StreetEditor& operator=(const StreetEditor&) = delete;

  /// Applies `edit`. Throws Error(Usage) naming the key for a node, edge or
  /// block the network does not have, or a bad value (a negative width, a zero
  /// scale); the state is then unchanged. Clears the redo list.
  EditReport apply(const StreetEdit& edit);
  /// Undoes the last edit (false when there is none); redo() applies it again.
  bool undo();
  bool redo();
  std::size_t undoSize() const;
  std::size_t redoSize() const;

  /// Sets (empty: clears) the label of parcel `parcel`; Error(Usage) when no parcel has that key.
  void setLabel(Key parcel, const std::string& label);
  /// Locks (or unlocks) parcel `parcel` (Lipp et al. 2011's anchored
  /// assignment): when its block is subdivided again, a locked parcel that
  /// still lies inside the block keeps its geometry and key, and the rest of
  /// the block is subdivided around it. Error(Usage) when no parcel has that key.
  void setLock(Key parcel, bool locked);

  /// The current network and parcels. parcelKeys()[i] is the key of
  /// parcels().parcels[i]; labels() by parcel key.
  const StreetNetwork& network() const;
  const GeneratedParcels& parcels() const;
  const std::vector<Key>& parcelKeys() const;
  const std::map<Key, std::string>& labels() const;
  const std::set<Key>& locked() const;
  const BlockOverrides& overrides() const;
  /// The parcels a fresh build of the current network and overrides gives,
  /// nothing reused: what parcels() must equal when no parcel is locked.
  GeneratedParcels freshParcels() const;
  /// A point of the input's CRS in the editor's local metres.
  Point toLocal(const Point& source) const;

  struct State;
  /// The current state, kept alive and unchanged while the editor goes on
  /// (for another thread to draw).
  class Snapshot {
  public:
    const StreetNetwork& network() const;
    const GeneratedParcels& parcels() const;
    const std::vector<Key>& parcelKeys() const;
    const std::map<Key, std::string>& labels() const;
    const std::set<Key>& locked() const;
    const BlockOverrides& overrides() const;

  private:
    friend class StreetEditor;
    std::shared_ptr<const State> state_;
  };
  Snapshot snapshot() const;

private:
  // The state of `network` with `overrides` and `labels`, reusing what
  // `previous` holds for unchanged entries (see StreetEditor.cpp).
  struct Attributes {
    std::map<Key, std::string> labels;
    std::set<Key> locked;
  };
  std::shared_ptr<const State> build(std::shared_ptr<const StreetNetwork> network, BlockOverrides overrides,
                                     Attributes attributes, const State* previous, EditReport* report) const;
  analysis::StreetBlockOptions blockOptions() const;
  // A copy of the current state with `change` applied to its attributes, made current.
  void changeAttributes(Key parcel, const std::function<void(Attributes&)>& change);
  std::shared_ptr<const State> current_;
  std::vector<std::shared_ptr<const State>> undo_, redo_;
  GenerateRequest request_;
  // With observed parcels: their data, and each block part's values derived
  // from them, by block key and part (BlockInputs::Entry without its shape).
  std::shared_ptr<const ObservedData> observed_;
  std::map<std::pair<Key, int>, BlockInputs::Entry> derived_;
  std::uint64_t serial_ = 0;  // the depth in the undo history of the state being built (new parcels' keys)
  // The faces and street surfaces of the networks built so far: an edit
  // overlays again only the faces it reached.
  analysis::StreetBlockCache cache_;
};

/// Reads an edits file: a JSON list of objects {"op": NAME, ...} with keys as
/// 16 hexadecimal digits (as streets.gpkg and blocks.gpkg write them) and
/// coordinates [x, y] in the input's CRS, converted with `toLocal`. Throws
/// Error(Input) naming the file, the edit's index and the member that is wrong.
std::vector<StreetEdit> readEdits(const std::string& path, const std::function<Point(const Point&)>& toLocal);

/// The edits file that readEdits reads back as `edits` (with `frame`'s
/// conversions): keys as 16 hexadecimal digits, points in the input's CRS.
Json editsJson(const std::vector<StreetEdit>& edits, const io::LocalFrame& frame);
/// Writes editsJson atomically into `path`, which must not be one of `inputs`. Throws Error(Io).
void writeEdits(const std::string& path, const std::vector<StreetEdit>& edits, const io::LocalFrame& frame,
                const std::vector<std::string>& inputs);

/// persistence.csv: per edit, its index and op, the blocks it subdivided again
/// and removed (counts, and the keys joined by ';'), the parcels of those
/// blocks before and after, the parcels after matched to one before (which
/// keep its key: keys_kept) and their share of the parcels before, seconds.
Table persistenceTable(const std::vector<EditReport>& reports);

/// The editor's parcels with their keys and labels: generatedParcelTable with
/// parcel_key the editor's key and a `label` column.
Table editedParcelTable(const StreetEditor& editor, std::vector<std::vector<Polygon>>* geometries);

/// `parcelscope edit`: the network and parcels of `request`, the edits of
/// `editsPath` applied in order; writes, all at once when complete,
/// DIR/parcels.gpkg (layer `parcels`, editedParcelTable), DIR/blocks.gpkg,
/// DIR/streets.gpkg, DIR/street_surface.gpkg (writeStreetLayers),
/// DIR/persistence.csv and DIR/run.json. An edit that fails stops the run
/// with its index and nothing written.
JobOutcome runEdit(const GenerateRequest& request, const std::string& editsPath, const std::string& outDir,
                   const ProgressFn& progress = {});
/// The same on the street network of comparison `request` (a session of
/// `compare --streets`): its observed parcels are read and grouped in the
/// network's blocks, and the editor starts from the parcels the comparison
/// generates (see StreetEditor's constructor from observed parcels), as the
/// application's editing mode does.
JobOutcome runEdit(const CompareRequest& request, const std::string& editsPath, const std::string& outDir,
                   const ProgressFn& progress = {});

}  // namespace parcelscope::pipeline
