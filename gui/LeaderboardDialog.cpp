#include "LeaderboardDialog.h"

#include <QFileDialog>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QTabWidget>
#include <QTableWidget>
#include <QVBoxLayout>

#include <cmath>
#include <variant>

#include "parcelscope/core/Error.h"
#include "parcelscope/viz/CompareFigures.h"

namespace parcelscope::gui {

namespace {

// A table's columns and rows into `widget`, numbers to 3 significant digits.
void fill(QTableWidget* widget, const Table& table) {
  widget->clear();
  widget->setColumnCount(static_cast<int>(table.columns.size()));
  widget->setRowCount(static_cast<int>(table.rows.size()));
  QStringList headers;
  for (const Column& c : table.columns) {
    headers << QString::fromStdString(c.name) + (c.unit.empty() ? "" : " (" + QString::fromStdString(c.unit) + ")");
  }
  widget->setHorizontalHeaderLabels(headers);
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    for (std::size_t c = 0; c < table.rows[r].size(); ++c) {
      const Value& v = table.rows[r][c];
      QString text;
      if (const auto* s = std::get_if<std::string>(&v)) {
        text = QString::fromStdString(*s);
      } else if (const auto* i = std::get_if<std::int64_t>(&v)) {
        text = QString::number(*i);
      } else if (const auto* d = std::get_if<double>(&v)) {
        text = std::isfinite(*d) ? QString::number(*d, 'g', 3) : QString("-");
      }
      auto* item = new QTableWidgetItem(text);
      item->setFlags(item->flags() & ~Qt::ItemIsEditable);
      widget->setItem(static_cast<int>(r), static_cast<int>(c), item);
    }
  }
  widget->resizeColumnsToContents();
}

}  // namespace

LeaderboardDialog::LeaderboardDialog(const pipeline::CompareRequest& request, QWidget* parent)
    : QDialog(parent), request_(request) {
  setWindowTitle("Every style against the observed parcels");
  auto* layout = new QVBoxLayout(this);
  status_ = new QLabel("Running every style on the same blocks...");
  status_->setWordWrap(true);
  layout->addWidget(status_);
  bar_ = new QProgressBar;
  bar_->setRange(0, 1000);
  layout->addWidget(bar_);
  auto* tabs = new QTabWidget;
  styles_ = new QTableWidget;
  layout_ = new QTableWidget;
  tabs->addTab(styles_, "Styles");
  tabs->addTab(layout_, "Layout measures");
  layout->addWidget(tabs, 1);
  auto* buttons = new QHBoxLayout;
  cancel_ = new QPushButton("Cancel");
  save_ = new QPushButton("Save...");
  save_->setEnabled(false);
  auto* close = new QPushButton("Close");
  buttons->addWidget(cancel_);
  buttons->addStretch(1);
  buttons->addWidget(save_);
  buttons->addWidget(close);
  layout->addLayout(buttons);
  resize(900, 420);
  connect(cancel_, &QPushButton::clicked, this, [this] { cancel(); });
  connect(close, &QPushButton::clicked, this, &QDialog::close);
  connect(save_, &QPushButton::clicked, this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(this, "Save the leaderboard into");
    if (!folder.isEmpty()) save(folder);
  });

  task_ = new BackgroundTask(
      [this](const ProgressFn& progress) {
        made_ = std::make_shared<pipeline::Leaderboard>(pipeline::leaderboard(request_, progress));
      },
      this);
  connect(task_, &BackgroundTask::progress, this, &LeaderboardDialog::progress);
  connect(task_, &BackgroundTask::finished, this, &LeaderboardDialog::done);
}

// The task (a child) ends first: QObject deletes children before this object's members go.
LeaderboardDialog::~LeaderboardDialog() { delete task_; }

void LeaderboardDialog::cancel() {
  task_->cancel();
  status_->setText("Cancelling...");
  cancel_->setEnabled(false);
}

void LeaderboardDialog::progress(double fraction, const QString& stage) {
  if (!cancel_->isEnabled()) return;  // cancelled
  bar_->setValue(static_cast<int>(1000 * fraction));
  status_->setText("Running every style on the same blocks: " + stage);
}

void LeaderboardDialog::done(const QString& error) {
  cancel_->setEnabled(false);
  error_ = error;
  if (error.isEmpty()) board_ = std::move(made_);
  bar_->setValue(board_ ? 1000 : bar_->value());
  if (board_) {
    fill(styles_, pipeline::leaderboardTable(*board_));
    fill(layout_, pipeline::layoutTable(pipeline::layoutRows(*board_)));
    status_->setText(QString("%1 styles on %2 blocks. Fit: KS area + KS width + KS aspect ratio, lower is closer; "
                             "blocks_best: blocks whose observed parcels the style fits best.")
                         .arg(board_->entries.size())
                         .arg(board_->observed->analysis.blocks.size()));
    save_->setEnabled(true);
  } else {
    status_->setText(error == "cancelled" ? QString("Cancelled.") : "Could not make the leaderboard: " + error);
  }
  emit finished();
}

bool LeaderboardDialog::save(const QString& folder) {
  if (!board_) return false;
  try {
    pipeline::CompareRequest withFigure = request_;  // the window's own request draws no figures
    withFigure.parameters["figures"] = 1;
    pipeline::saveLeaderboard(*board_, withFigure, folder.toStdString(), viz::drawLeaderboard);
    status_->setText("Saved into " + folder);
    return true;
  } catch (const std::exception& e) {
    error_ = QString::fromStdString(e.what());
    status_->setText(error_);
    return false;
  }
}

}  // namespace parcelscope::gui
