#pragma once
// The ParcelScope window: observed and procedural parcels side by side with
// linked cameras, overlaid histograms and the comparison numbers, a parameter
// panel and a block panel. Every change is an edit of the request a
// pipeline::Controller holds, which says what to hand to a SessionWorker (the
// same library code as `parcelscope compare`) and what to do with each of its
// reports; this class only gathers input and shows results.
#include <QElapsedTimer>
#include <QImage>
#include <QMainWindow>
#include <QPointer>
#include <QString>
#include <QStringList>
#include <QThread>

#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>

#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include "SessionWorker.h"
#include "StreetEditWorker.h"
#include "parcelscope/analysis/RoadGraph.h"
#include "parcelscope/pipeline/CompareSession.h"
#include "parcelscope/pipeline/Controller.h"
#include "parcelscope/viz/Figures.h"

class QCheckBox;
class QCloseEvent;
class QScrollArea;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QMenu;
class QProgressBar;
class QPushButton;
class QTableWidget;
class QTextBrowser;
class QVTKOpenGLStereoWidget;
class vtkChartXY;
class vtkContextView;
class vtkGenericOpenGLRenderWindow;

namespace parcelscope::gui {

class ChartStyle;
class BackgroundTask;
class LeaderboardDialog;
class MapView;
class ParameterPanel;

class MainWindow : public QMainWindow {
  Q_OBJECT
public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  /// What the application sets before its QApplication exists: VTK's OpenGL
  /// surface format, and views drawn to the screen as soon as they are
  /// rendered (QT_QPA_UPDATE_IDLE_TIME 0 unless set: Qt otherwise waits 5 ms
  /// before each window's update, a tenth of a street drag).
  static void prepareApplication();

  /// Opens `path` (asks for a layer when it holds several and none is given).
  void openFile(const QString& path, const QString& layer = {}, const QString& where = {}, const QString& crs = {});
  /// Opens the bundled sample.
  void openSample();
  /// Reads the open input again keeping only the features that match `where`
  /// (an OGR SQL attribute filter, as the command line's --where; empty: all).
  void setFilter(const QString& where);
  /// Blocks from the street centre lines of `path` (the command line's
  /// --streets, with --width-field and --name-field; empty: none); drawn over
  /// both views. removeStreets() goes back to blocks grouped from the parcels.
  void openStreets(const QString& path, const QString& widthField = {}, const QString& nameField = {});
  void removeStreets();
  /// Restores input, parameters, overrides and seed from a session file.
  void openSession(const QString& path);
  void saveSession(const QString& path);
  /// Exports figure `name` (viz::figureNames()), the tables or the generated parcels.
  void exportFigure(const QString& name, const QString& path, int width = 1800, int height = 900);
  void exportTables(const QString& folder);
  void exportParcels(const QString& path);

  /// Analysis > Compare every style: the leaderboard of every style on the
  /// open input with the current parameters (`compare --style all`), made in
  /// the background in its own window; null when nothing is open yet.
  LeaderboardDialog* showLeaderboard();
  /// Analysis > Fit to observed: `parcelscope calibrate` on the open input
  /// (in the background, with progress and Cancel); when it ends, every block
  /// gets the style of least distance to its observed parcels as its override
  /// (saved with the session) and the views update; fitSummary() then says
  /// what changed (empty when it failed or was cancelled: see lastError()).
  void fitToObserved();
  /// The text the last Fit to observed showed (before and after measures).
  QString fitSummary() const { return fitSummary_; }
  /// A Fit to observed is under way.
  bool fitting() const { return fitTask_ != nullptr; }
  /// Cancels the Fit to observed under way.
  void cancelFit();

  /// Sets one parameter as the user would (explicit from now on) and regenerates.
  void setParameter(const std::string& name, double value);
  void setStyle(const QString& style);
  void setColourBy(const QString& quantity);
  /// Shows or hides the parcel outlines in both views (View > Parcel outlines).
  void setOutlinesVisible(bool visible);
  /// Fits both views to the observed blocks (View > Zoom to extent, Home);
  /// nothing before the first result.
  void zoomToExtent();
  /// Selects the observed block with this index (-1: none).
  void selectBlock(int block);
  /// A click at (x, y) (local metres) in the observed or the procedural view:
  /// selects the parcel there and its block (the inspector shows both);
  /// outside every parcel, the block there (or none).
  void inspectAt(bool procedural, double x, double y);
  /// The parcel the inspector shows: an index into the observed parcels or the
  /// generated ones (`procedural`), -1 when none.
  int selectedParcel() const { return selectedParcel_; }
  bool selectedParcelIsProcedural() const { return selectedProcedural_; }
  /// The inspector's text (the selected parcel's attributes and metrics).
  QString parcelInfoText() const;
  /// Input coordinates of local point (x, y) as the views' readout shows them:
  /// "lon -71.10245, lat 42.36849" for a geographic input, else "x ..., y ... (CRS)".
  QString coordinateText(double x, double y) const;
  /// Help > About: version, licences of ParcelScope, its libraries and the bundled data.
  static QString aboutText();
  /// Block overrides differ from those last saved or opened (quitting asks first).
  bool unsavedOverrides() const;
  /// The notice bar (blue, above the views): what an edit did besides its own
  /// change (e.g. per-block bounds turned off); empty when hidden.
  QString notice() const;
  /// Overrides the selected block's style and parameters, or clears its override.
  void overrideSelectedBlock(const QString& style, const ParameterValues& parameters);
  void clearSelectedOverride();

  /// The window as on screen: its widgets with the views' OpenGL images
  /// (which QWidget::grab leaves out, as each view is a native window).
  QImage screenshot();

  const pipeline::CompareRequest& request() const { return controller_.request(); }
  std::shared_ptr<const pipeline::CompareResult> result() const { return controller_.shownResult(); }
  /// The request being edited and the bookkeeping of its updates.
  const pipeline::Controller& controller() const { return controller_; }
  ParameterPanel* parameterPanel() const { return panel_; }
  MapView* observedView() const { return observedView_; }
  MapView* proceduralView() const { return proceduralView_; }
  QTableWidget* numbers() const { return numbers_; }
  /// The histogram chart's title and series counts, as shown.
  QString histogramTitle() const;
  /// Every text of the histogram chart: title, axis titles, series labels.
  QStringList histogramTexts() const;
  std::vector<std::vector<int>> histogramCounts() const { return histogramCounts_; }
  int selectedBlock() const { return selected_; }
  /// The message shown in the window's error bar (empty when none).
  QString lastError() const;
  /// Milliseconds from the last submitted change to views and histograms drawn.
  double lastLatencyMs() const { return lastLatencyMs_; }
  /// Milliseconds from the last submitted change to every number shown
  /// (after the views when the neighbours and street access were measured
  /// afterwards; see UpdateReport::contextPending).
  double lastCompleteMs() const { return lastCompleteMs_; }
  /// Milliseconds from the last completed change to the first views drawn for
  /// it (a result in between, while many blocks are regenerated, or the final one).
  double lastFirstViewMs() const { return lastFirstViewMs_; }
  /// Where the last drawn change's time went (ms): the library until its
  /// result arrived (0 for a change the window makes alone), the map layers
  /// rebuilt and recoloured, the histogram, the numbers and block text, and
  /// the views drawn into their buffers. lastLatencyMs is about their sum.
  struct UpdateTimings {
    double library = 0, layers = 0, histogram = 0, text = 0, views = 0;
    /// Within `library`: the session's update, and its generate and metrics stages.
    double update = 0, generate = 0, metrics = 0;
  };
  UpdateTimings lastTimings() const { return lastTimings_; }
  /// True while an update is queued or under way.
  bool busy() const { return controller_.busy(); }

  // ---- Street editing (Edit menu; Vanegas et al. 2012, section 5) ------------
  // The procedural view shows the shown comparison's street network, edited:
  // drag a node and the parcels of the blocks around it follow; draw a street,
  // delete one, change its width, curve it by dragging its control points;
  // click a parcel to label or lock it (its key, label and lock follow it
  // across edits). The same pipeline::StreetEditor as `parcelscope edit`, on
  // its own thread (StreetEditWorker). Save edits writes them as the command
  // line's edits file.

  /// Starts (or ends) editing the streets of the comparison shown; false when
  /// it has no street network. The parameter panel is disabled meanwhile.
  bool setEditing(bool on);
  bool editing() const { return editing_; }
  /// The editor's state shown; null before the first arrives.
  const StreetEditState* editState() const { return editState_ ? &*editState_ : nullptr; }
  /// The gestures of the procedural view, in local metres: a press on a node
  /// or a control point starts a drag (true), each move applies it, the drop
  /// ends it; a press elsewhere pans. A drag is one step of undo.
  bool pressAt(double x, double y);
  void dragTo(double x, double y);
  void dropAt(double x, double y);
  /// A click while editing: drawing a street, its end; else selects the node,
  /// the street or the parcel there (in that order, within a few pixels).
  void editClickAt(double x, double y);
  void undoEdit();
  void redoEdit();
  /// Edit > Draw street: the next two clicks are a new street's ends (a click
  /// on a node joins it there).
  void setDrawingStreet(bool on);
  void deleteSelectedStreet();
  void setSelectedStreetWidth(double width);
  /// Curves the selected street (control points at its thirds) or straightens it.
  void setSelectedStreetCurved(bool curved);
  void labelSelectedParcel(const QString& label);
  void lockSelectedParcel(bool locked);
  /// Writes the edits applied (undone ones left out) as the edits file of
  /// `parcelscope edit SESSION --edits FILE` (keys, coordinates in the input's CRS).
  void saveEdits(const QString& path);
  /// Edits submitted whose state is not drawn yet.
  bool editBusy() const { return !editStarted_.empty(); }
  Key selectedNode() const { return selectedNode_; }
  Key selectedStreet() const { return selectedStreet_; }
  Key selectedEditParcel() const { return selectedEditParcel_; }
  /// Milliseconds from the last drag move (or other edit) submitted to the
  /// procedural view drawn with its result, and where they went.
  double lastEditLatencyMs() const { return lastEditLatencyMs_; }
  struct EditTimings {
    /// Submitted to state arrived (of which the editor's own time), the
    /// parcel layer, the streets, colours, handles and inspector, the view drawn.
    double library = 0, editor = 0, parcels = 0, streets = 0, handles = 0, views = 0;
  };
  EditTimings lastEditTimings() const { return lastEditTimings_; }

signals:
  /// Views, histograms and numbers show the result of request serial `serial`.
  void viewsUpdated(qint64 serial);
  void errorShown(const QString& message);
  /// A result in between is shown (see pipeline::CompareSession::PartialFn).
  void partialShown(qint64 serial);
  /// The numbers of request serial `serial` are complete (its neighbours and
  /// street access were measured after its views were drawn).
  void contextCompleted(qint64 serial);
  /// The procedural view shows the editor's state that answers command `serial` (0: the first state).
  void editShown(qint64 serial);

protected:
  /// With unsaved block overrides, asks Save / Discard / Cancel first.
  void closeEvent(QCloseEvent* event) override;
  void dragEnterEvent(QDragEnterEvent* event) override;
  void dropEvent(QDropEvent* event) override;

private:
  void buildMenus();
  void buildEditMenu();
  /// The procedural layer from `generated` (grouped by block, so that only
  /// the layer parts of changed blocks are built again).
  void drawProceduralLayer(const pipeline::GeneratedParcels& generated);
  void drawEditState(const StreetEditState& state);
  /// The centre lines of `graph`'s streets (its boundary left out), as the views draw them.
  static std::vector<std::vector<Point>> centreLines(const analysis::RoadGraph& graph);
  /// The handles of the editor's network and selection.
  void drawHandles();
  void showEditParcel();
  qint64 submitEdit(const StreetEditWorker::Command& command);
  void updateEditActions();
  /// The node, the street or the control point of the selected street within
  /// `pixels` of (x, y); -1 when none.
  int nodeNear(double x, double y, double pixels) const;
  int streetNear(double x, double y, double pixels) const;
  int controlNear(double x, double y, double pixels) const;
  QWidget* buildControls();
  void submit();
  void showReport(const UpdateReport& report);
  void drawReport(const UpdateReport& report);
  /// The numbers of request `serial` are complete: timing and contextCompleted.
  void noteContextCompleted(qint64 serial);
  /// The controls show the request being edited (after a session was read,
  /// or a failure brought back the last good request).
  void showRequest();
  /// Shows `message` in the error bar, in the window's words (see windowWording).
  void showError(const QString& message);
  /// Enables what needs a result (exports, save session, block override, zoom
  /// to extent) or an input (set input CRS) once there is one.
  void updateActions();
  void setBlockInfo(const QString& html);
  void showParcel();
  void showNotice(const QString& text);
  /// The procedural view's title: the style and seed of the request shown, or,
  /// for a result in between left by a cancelled update, what it holds.
  void titleProcedural();
  /// The overrides as a session file holds them (to compare with the saved ones).
  std::string overridesText() const;
  void markOverridesSaved();
  /// Recolours the views; returns whether the observed view changed (it is
  /// drawn again only then). `observedChanged`: its data changed.
  bool recolour(bool observedChanged);
  void drawHistogram();
  void fillNumbers();
  void showBlock();
  /// Puts `input` first in File > Open recent, with its layer, filter and CRS
  /// (QSettings), which opening it from there uses again.
  void rememberRecent(const io::ReadOptions& input);
  void refreshRecent();
  void exportFigureDialog();
  /// Runs `write` on the last complete result; says `done` or shows the error.
  void exportWith(const QString& done, const std::function<void()>& write);
  /// File > Set input CRS: for the input whose open failed last, else the one open.
  void askForCrs();
  /// Asks for a CRS and opens `input` again with it.
  void askForCrs(const io::ReadOptions& input);
  /// File > Filter features: asks for an attribute filter for the open input.
  void askForFilter();
  void askForStreets();

  QThread thread_;
  SessionWorker* worker_;
  QPointer<LeaderboardDialog> leaderboard_;
  QAction* leaderboardAction_ = nullptr;
  QAction* fitAction_ = nullptr;
  BackgroundTask* fitTask_ = nullptr;
  QString fitSummary_;
  pipeline::Controller controller_;
  std::map<qint64, QElapsedTimer> started_;
  std::map<qint64, QElapsedTimer> completeStarted_;  ///< views drawn, numbers not complete yet
  /// The result whose parcels the procedural layer draws (it reads them again on zoom).
  std::shared_ptr<const pipeline::CompareResult> layerResult_;
  double lastLatencyMs_ = 0, lastCompleteMs_ = 0;
  UpdateTimings lastTimings_;
  double firstViewMs_ = -1, lastFirstViewMs_ = 0;
  int selected_ = -1;
  std::vector<std::vector<int>> histogramCounts_;
  /// The observed blocks' extent, for View > Zoom to extent (set with the first result of an input).
  std::optional<Box> extent_;
  /// The input File > Open (or the recent list, drag and drop) opened last,
  /// until a result of it is drawn: then it goes to the recent files.
  std::optional<io::ReadOptions> openedInput_;
  std::string shownQuantity_;
  viz::ColourScale shownScale_;
  bool selectionChanged_ = false;

  MapView* observedView_;
  MapView* proceduralView_;
  QVTKOpenGLStereoWidget* histogramWidget_;
  vtkNew<vtkGenericOpenGLRenderWindow> histogramWindow_;
  vtkNew<vtkContextView> histogramView_;
  vtkNew<vtkChartXY> chart_;
  vtkSmartPointer<ChartStyle> histogramStyle_;
  QTableWidget* numbers_;
  QLabel* errorBar_;
  QLabel* noticeBar_;
  QScrollArea* controlsScroll_;
  QTextBrowser* parcelInfo_;
  QString parcelInfoHtml_;
  int selectedParcel_ = -1;
  bool selectedProcedural_ = false;
  /// The result shown is one in between (blocks done of total), and whether its update was cancelled.
  bool shownPartial_ = false, partialCancelled_ = false;
  int partialDone_ = 0, partialTotal_ = 0;
  /// Per-block bounds were turned off by a bound's slider: the parcel count before, for the notice.
  std::optional<std::size_t> boundsNoticeBefore_;
  QString boundsNotice_;
  /// The overrides when last saved or opened (overridesText()).
  std::string savedOverrides_;
  QLabel* status_;
  QProgressBar* progress_;
  QPushButton* cancel_;
  QComboBox* style_;
  QComboBox* colourBy_;
  QCheckBox* perBlockBounds_;
  ParameterPanel* panel_;
  QTextBrowser* blockInfo_;
  QString blockInfoHtml_;  // what blockInfo_ shows
  QComboBox* blockStyle_;
  QPushButton* overrideBlock_;
  QPushButton* clearOverride_;
  std::map<std::string, std::pair<QCheckBox*, QDoubleSpinBox*>> blockParameters_;
  /// The block whose values the override panel shows (0: none yet).
  Key panelBlock_ = 0;
  /// The value block `block` (an index into the observed blocks) is subdivided
  /// with for parameter `name`: its override's, else its own derived bound
  /// (with per-block bounds, for a bound the user did not set), else the run's.
  double blockValue(const pipeline::CompareResult& result, int block, const std::string& name) const;
  /// Fills the override panel with the selected block's values.
  void fillOverridePanel(const pipeline::CompareResult& result);
  /// The comparison's street network as drawn (centre lines, street surface),
  /// drawn again in the procedural view when editing ends.
  std::vector<std::vector<Point>> comparisonLines_;
  std::vector<Polygon> comparisonSurface_;
  // Street editing.
  QThread editThread_;
  StreetEditWorker* editWorker_;
  bool editing_ = false;
  std::optional<StreetEditState> editState_;
  Key selectedNode_ = 0, selectedStreet_ = 0, selectedEditParcel_ = 0;
  /// The drag under way: its gesture, what it moves (a node, or control point
  /// `control` of the selected street).
  qint64 gesture_ = 0, gestures_ = 0;
  Key dragNode_ = 0;
  int dragControl_ = -1;
  bool dragMoved_ = false;
  std::optional<std::array<Point, 2>> dragControls_;  ///< the street's control points when the drag began
  std::optional<Point> streetStart_;                  ///< drawing a street: its first end
  Key streetStartNode_ = 0;
  bool drawingStreet_ = false;
  std::map<qint64, QElapsedTimer> editStarted_;
  double lastEditLatencyMs_ = 0;
  EditTimings lastEditTimings_;
  QAction* editAction_ = nullptr;
  QAction* undoAction_ = nullptr;
  QAction* redoAction_ = nullptr;
  QAction* drawStreetAction_ = nullptr;
  QAction* deleteStreetAction_ = nullptr;
  QAction* widthAction_ = nullptr;
  QAction* curveAction_ = nullptr;
  QAction* labelAction_ = nullptr;
  QAction* lockAction_ = nullptr;
  QAction* saveEditsAction_ = nullptr;
  QMenu* recentMenu_;
  QAction* setCrsAction_;
  QAction* filterAction_;
  QAction* streetsAction_;
  QAction* removeStreetsAction_;
  QAction* saveSessionAction_;
  QMenu* exportMenu_;
  QAction* zoomToExtentAction_;
};

}  // namespace parcelscope::gui
