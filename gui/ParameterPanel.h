#pragma once
// A slider and a spin box per parameter, built from the parameters'
// descriptions (name, help, unit, range, default), so the GUI offers exactly
// what the command line takes. Wide ranges get a logarithmic slider.
#include <QWidget>

#include <map>
#include <vector>

#include "parcelscope/core/Parameter.h"

class QDoubleSpinBox;
class QSlider;

namespace parcelscope::gui {

class ParameterPanel : public QWidget {
  Q_OBJECT
public:
  ParameterPanel(const std::vector<ParameterDescription>& parameters, QWidget* parent = nullptr);
  /// Shows `values` without emitting changed().
  void setValues(const ParameterValues& values);
  double value(const std::string& name) const;
  QSlider* slider(const std::string& name) const;
  QDoubleSpinBox* spinBox(const std::string& name) const;

signals:
  void changed(const QString& name, double value);

private:
  struct Row {
    ParameterDescription description;
    QSlider* slider = nullptr;
    QDoubleSpinBox* spin = nullptr;
    bool logarithmic = false;
  };
  int toSlider(const Row& row, double value) const;
  double fromSlider(const Row& row, int position) const;
  std::map<std::string, Row> rows_;
  bool quiet_ = false;
};

}  // namespace parcelscope::gui
