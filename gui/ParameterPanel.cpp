#include "ParameterPanel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QGridLayout>
#include <QGroupBox>
#include <QLabel>
#include <QSignalBlocker>
#include <QSlider>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

namespace parcelscope::gui {

namespace {
constexpr int kSteps = 1000;
}

ParameterPanel::ParameterPanel(const std::vector<ParameterDescription>& parameters, QWidget* parent) : QWidget(parent) {
  auto* column = new QVBoxLayout(this);
  column->setContentsMargins(0, 0, 0, 0);
  for (const auto& [group, members] : groupParameters(parameters)) {
    auto* box = new QGroupBox(QString::fromStdString(group), this);
    box->setObjectName(QString::fromStdString("group-" + group));
    auto* grid = new QGridLayout(box);
    int line = 0;
    for (const ParameterDescription& d : members) addRow(grid, line++, d);
    grid->setColumnStretch(1, 1);
    column->addWidget(box);
    groups_[group] = box;
  }
  column->addStretch(1);
  setValues(defaultValues(parameters));
}

void ParameterPanel::addRow(QGridLayout* grid, int line, const ParameterDescription& d) {
  QWidget* box = grid->parentWidget();
  const QString help = QString::fromStdString(d.help);
  const std::string name = d.name;
  Row row;
  row.description = d;
  auto* label = new QLabel(QString::fromStdString(d.name + (d.unit.empty() ? "" : " (" + d.unit + ")")), box);
  label->setToolTip(help);
  grid->addWidget(label, line, 0);
  if (d.kind == ParameterKind::Enum) {
    row.combo = new QComboBox(box);
    row.combo->setObjectName(QString::fromStdString("combo-" + d.name));
    for (const std::string& l : d.labels) row.combo->addItem(QString::fromStdString(l));
    row.combo->setToolTip(help);
    grid->addWidget(row.combo, line, 1, 1, 2);
    rows_[name] = row;
    connect(row.combo, qOverload<int>(&QComboBox::currentIndexChanged), this, [this, name](int index) {
      if (index >= 0) emitChanged(name, rows_.at(name).description.minimum + index);
    });
    return;
  }
  if (d.kind == ParameterKind::Boolean) {
    row.check = new QCheckBox(box);
    row.check->setObjectName(QString::fromStdString("check-" + d.name));
    row.check->setToolTip(help);
    grid->addWidget(row.check, line, 1, 1, 2);
    rows_[name] = row;
    connect(row.check, &QCheckBox::toggled, this, [this, name](bool on) { emitChanged(name, on ? 1 : 0); });
    return;
  }
  row.logarithmic = d.minimum >= 0 && d.maximum - d.minimum > 1000 && !d.integer();
  if (row.logarithmic) {
    // A slider some 250 px long over six decades moved a bound several-fold
    // per few pixels (W_max from 30 m to over 1,000 m in 40 px). It spans the
    // values that matter instead, default / 10 to default x 10 (W_max: 3 to
    // 300 m, about 2 % a pixel), logarithmically; the spin box takes the
    // whole range, and the slider rests at its end beyond it.
    const double centre = d.defaultValue > 0 ? d.defaultValue : std::max(1.0, d.maximum / 1e4);
    row.low = std::max(d.minimum > 0 ? d.minimum : 0.0, centre / 10);
    row.high = std::min(d.maximum, centre * 10);
  }
  row.slider = new QSlider(Qt::Horizontal, box);
  row.slider->setObjectName(QString::fromStdString("slider-" + d.name));
  row.slider->setToolTip(help);
  row.spin = new QDoubleSpinBox(box);
  row.spin->setObjectName(QString::fromStdString("spin-" + d.name));
  row.spin->setRange(d.minimum, d.maximum);
  row.spin->setDecimals(d.integer() ? 0 : (d.maximum - d.minimum <= 10 ? 3 : 1));
  row.spin->setSingleStep(d.integer() ? 1 : std::max(0.001, (d.maximum - d.minimum) / 1000));
  row.spin->setKeyboardTracking(false);
  row.spin->setToolTip(help);
  if (d.integer() && d.maximum - d.minimum <= kSteps) {
    row.slider->setRange(static_cast<int>(d.minimum), static_cast<int>(d.maximum));
  } else {
    row.slider->setRange(0, kSteps);
  }
  grid->addWidget(row.slider, line, 1);
  grid->addWidget(row.spin, line, 2);
  rows_[name] = row;
  connect(row.slider, &QSlider::valueChanged, this, [this, name](int position) {
    if (quiet_) return;
    const Row& r = rows_.at(name);
    const double v = fromSlider(r, position);
    {
      const QSignalBlocker block(r.spin);
      r.spin->setValue(v);
    }
    emitChanged(name, r.spin->value());
  });
  connect(row.spin, qOverload<double>(&QDoubleSpinBox::valueChanged), this, [this, name](double v) {
    if (quiet_) return;
    const Row& r = rows_.at(name);
    {
      const QSignalBlocker block(r.slider);
      r.slider->setValue(toSlider(r, v));
    }
    emitChanged(name, v);
  });
}

void ParameterPanel::emitChanged(const std::string& name, double value) {
  if (!quiet_) emit changed(QString::fromStdString(name), value);
}

int ParameterPanel::toSlider(const Row& row, double v) const {
  const ParameterDescription& d = row.description;
  if (row.slider->maximum() != kSteps || row.slider->minimum() != 0) return static_cast<int>(std::lround(v));
  double t = row.logarithmic ? std::log(std::max(v, row.low) / row.low) / std::log(row.high / row.low)
                             : (v - d.minimum) / (d.maximum - d.minimum);
  return static_cast<int>(std::lround(std::clamp(t, 0.0, 1.0) * kSteps));
}

double ParameterPanel::fromSlider(const Row& row, int position) const {
  const ParameterDescription& d = row.description;
  if (row.slider->maximum() != kSteps || row.slider->minimum() != 0) return position;
  const double t = static_cast<double>(position) / kSteps;
  double v =
      row.logarithmic ? row.low * std::exp(t * std::log(row.high / row.low)) : d.minimum + t * (d.maximum - d.minimum);
  // Three significant digits: a slider position names a round value.
  if (row.logarithmic && v > 0) {
    const double unit = std::pow(10.0, std::floor(std::log10(v)) - 2);
    v = std::round(v / unit) * unit;
  }
  if (d.integer()) v = std::round(v);
  return std::clamp(v, d.minimum, d.maximum);
}

void ParameterPanel::setValues(const ParameterValues& values) {
  quiet_ = true;
  for (auto& [name, row] : rows_) {
    const auto it = values.find(name);
    if (it == values.end()) continue;
    if (row.combo) {
      row.combo->setCurrentIndex(static_cast<int>(std::lround(it->second - row.description.minimum)));
    } else if (row.check) {
      row.check->setChecked(it->second != 0);
    } else {
      row.spin->setValue(it->second);
      // A slider that already names this value stays put: a rounded value may
      // map back to the next position, which would move a slider being dragged.
      const double shown = fromSlider(row, row.slider->value());
      if (std::abs(shown - row.spin->value()) > 0.5 * std::pow(10.0, -row.spin->decimals()) + 1e-12)
        row.slider->setValue(toSlider(row, it->second));
    }
  }
  quiet_ = false;
}

double ParameterPanel::value(const std::string& name) const {
  const Row& row = rows_.at(name);
  if (row.combo) return row.description.minimum + row.combo->currentIndex();
  if (row.check) return row.check->isChecked() ? 1 : 0;
  return row.spin->value();
}
QSlider* ParameterPanel::slider(const std::string& name) const { return rows_.at(name).slider; }
QDoubleSpinBox* ParameterPanel::spinBox(const std::string& name) const { return rows_.at(name).spin; }
QComboBox* ParameterPanel::comboBox(const std::string& name) const { return rows_.at(name).combo; }
QCheckBox* ParameterPanel::checkBox(const std::string& name) const { return rows_.at(name).check; }
QGroupBox* ParameterPanel::groupBox(const std::string& group) const {
  const auto it = groups_.find(group);
  return it == groups_.end() ? nullptr : it->second;
}

}  // namespace parcelscope::gui
