#pragma once
// Analysis > Compare every style: the leaderboard of `compare --style all`
// (pipeline::leaderboard, the same library code) for the open input and
// parameters, made in a background thread with progress and Cancel, shown as
// two tables (every style against the observed parcels; the layout measures
// of Yang et al. 2013) and saved as the command line writes it.
#include <QDialog>
#include <QString>

#include <memory>

#include "BackgroundTask.h"

#include "parcelscope/pipeline/Leaderboard.h"

class QLabel;
class QProgressBar;
class QPushButton;
class QTableWidget;

namespace parcelscope::gui {

class LeaderboardDialog : public QDialog {
  Q_OBJECT
public:
  /// Starts making the leaderboard of `request` (its style is ignored).
  LeaderboardDialog(const pipeline::CompareRequest& request, QWidget* parent = nullptr);
  ~LeaderboardDialog() override;

  /// Asks the run under way to stop (Cancel).
  void cancel();
  /// Writes the leaderboard's tables, figure and run record into `folder`
  /// (as `compare --style all --out FOLDER`); false, with error() set, when it cannot.
  bool save(const QString& folder);

  bool running() const { return task_->running(); }
  /// The leaderboard once made; null before, or after a failure or Cancel.
  const pipeline::Leaderboard* board() const { return board_.get(); }
  QString error() const { return error_; }
  QTableWidget* styles() const { return styles_; }
  QTableWidget* layout() const { return layout_; }

signals:
  /// The run ended: made, failed or cancelled.
  void finished();

private:
  void progress(double fraction, const QString& stage);
  void done(const QString& error);

  pipeline::CompareRequest request_;
  std::shared_ptr<pipeline::Leaderboard> made_;  ///< written by the task's thread, read once it ended
  std::shared_ptr<const pipeline::Leaderboard> board_;
  QString error_;
  BackgroundTask* task_;
  QLabel* status_;
  QProgressBar* bar_;
  QPushButton* cancel_;
  QPushButton* save_;
  QTableWidget* styles_;
  QTableWidget* layout_;
};

}  // namespace parcelscope::gui
