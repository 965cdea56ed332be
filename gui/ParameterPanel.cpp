#include "ParameterPanel.h"

#include <QDoubleSpinBox>
#include <QGridLayout>
#include <QLabel>
#include <QSignalBlocker>
#include <QSlider>

#include <algorithm>
#include <cmath>

namespace parcelscope::gui {

namespace {
constexpr int kSteps = 1000;
}

ParameterPanel::ParameterPanel(const std::vector<ParameterDescription>& parameters, QWidget* parent)
    : QWidget(parent) {
  auto* grid = new QGridLayout(this);
  grid->setContentsMargins(0, 0, 0, 0);
  int line = 0;
  for (const ParameterDescription& d : parameters) {
    Row row;
    row.description = d;
    row.logarithmic = d.minimum >= 0 && d.maximum - d.minimum > 1000 && !d.integer;
    auto* label = new QLabel(QString::fromStdString(d.name + (d.unit.empty() ? "" : " (" + d.unit + ")")), this);
    label->setToolTip(QString::fromStdString(d.help));
    row.slider = new QSlider(Qt::Horizontal, this);
    row.slider->setObjectName(QString::fromStdString("slider-" + d.name));
    row.slider->setToolTip(QString::fromStdString(d.help));
    row.spin = new QDoubleSpinBox(this);
    row.spin->setObjectName(QString::fromStdString("spin-" + d.name));
    row.spin->setRange(d.minimum, d.maximum);
    row.spin->setDecimals(d.integer ? 0 : (d.maximum - d.minimum <= 10 ? 3 : 1));
    row.spin->setSingleStep(d.integer ? 1 : std::max(0.001, (d.maximum - d.minimum) / 1000));
    row.spin->setKeyboardTracking(false);
    row.spin->setToolTip(QString::fromStdString(d.help));
    if (d.integer && d.maximum - d.minimum <= kSteps) {
      row.slider->setRange(static_cast<int>(d.minimum), static_cast<int>(d.maximum));
    } else {
      row.slider->setRange(0, kSteps);
    }
    grid->addWidget(label, line, 0);
    grid->addWidget(row.slider, line, 1);
    grid->addWidget(row.spin, line, 2);
    ++line;
    const std::string name = d.name;
    rows_[name] = row;
    connect(row.slider, &QSlider::valueChanged, this, [this, name](int position) {
      if (quiet_) return;
      const Row& r = rows_.at(name);
      const double v = fromSlider(r, position);
      {
        const QSignalBlocker block(r.spin);
        r.spin->setValue(v);
      }
      emit changed(QString::fromStdString(name), r.spin->value());
    });
    connect(row.spin, qOverload<double>(&QDoubleSpinBox::valueChanged), this, [this, name](double v) {
      if (quiet_) return;
      const Row& r = rows_.at(name);
      {
        const QSignalBlocker block(r.slider);
        r.slider->setValue(toSlider(r, v));
      }
      emit changed(QString::fromStdString(name), v);
    });
  }
  grid->setColumnStretch(1, 1);
  setValues(defaultValues(parameters));
}

int ParameterPanel::toSlider(const Row& row, double v) const {
  const ParameterDescription& d = row.description;
  if (row.slider->maximum() != kSteps || row.slider->minimum() != 0) return static_cast<int>(std::lround(v));
  double t = row.logarithmic ? std::log1p(v - d.minimum) / std::log1p(d.maximum - d.minimum)
                             : (v - d.minimum) / (d.maximum - d.minimum);
  return static_cast<int>(std::lround(std::clamp(t, 0.0, 1.0) * kSteps));
}

double ParameterPanel::fromSlider(const Row& row, int position) const {
  const ParameterDescription& d = row.description;
  if (row.slider->maximum() != kSteps || row.slider->minimum() != 0) return position;
  const double t = static_cast<double>(position) / kSteps;
  double v = row.logarithmic ? d.minimum + std::expm1(t * std::log1p(d.maximum - d.minimum))
                             : d.minimum + t * (d.maximum - d.minimum);
  if (d.integer) v = std::round(v);
  return std::clamp(v, d.minimum, d.maximum);
}

void ParameterPanel::setValues(const ParameterValues& values) {
  quiet_ = true;
  for (auto& [name, row] : rows_) {
    const auto it = values.find(name);
    if (it == values.end()) continue;
    row.spin->setValue(it->second);
    row.slider->setValue(toSlider(row, it->second));
  }
  quiet_ = false;
}

double ParameterPanel::value(const std::string& name) const { return rows_.at(name).spin->value(); }
QSlider* ParameterPanel::slider(const std::string& name) const { return rows_.at(name).slider; }
QDoubleSpinBox* ParameterPanel::spinBox(const std::string& name) const { return rows_.at(name).spin; }

}  // namespace parcelscope::gui
