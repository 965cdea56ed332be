#pragma once
// The parameters' controls, built from their descriptions (name, help, unit,
// range, default, group, kind), so the GUI offers exactly what the command
// line takes: one box per group, and in it a slider and a spin box per real or
// integer parameter (wide ranges get a logarithmic slider over the values that
// matter, default / 10 to default x 10; the spin box takes the whole range), a combo box of the
// labels per enum, a check box per boolean.
#include <QString>
#include <QWidget>

#include <map>
#include <vector>

#include "parcelscope/core/Parameter.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QGridLayout;
class QGroupBox;
class QSlider;

namespace parcelscope::gui {

class ParameterPanel : public QWidget {
  Q_OBJECT
public:
  /// One group box per ParameterDescription::group (titled with it, object name
  /// "group-<group>"), in the order the groups first appear in `parameters`.
  /// Object names: "slider-<name>" and "spin-<name>" (real and integer),
  /// "combo-<name>" (enum), "check-<name>" (boolean).
  ParameterPanel(const std::vector<ParameterDescription>& parameters, QWidget* parent = nullptr);
  /// Shows `values` without emitting changed().
  void setValues(const ParameterValues& values);
  /// The value shown (an enum's the number of its label, a boolean's 0 or 1).
  double value(const std::string& name) const;
  /// The slider and spin box of a real or integer parameter; null for an enum or a boolean.
  QSlider* slider(const std::string& name) const;
  QDoubleSpinBox* spinBox(const std::string& name) const;
  /// Null unless the parameter is an enum.
  QComboBox* comboBox(const std::string& name) const;
  /// Null unless the parameter is a boolean.
  QCheckBox* checkBox(const std::string& name) const;
  /// The box of `group`, null when no parameter is in it.
  QGroupBox* groupBox(const std::string& group) const;

signals:
  /// The user changed parameter `name` to `value` (enum and boolean: a number, as the run records hold).
  void changed(const QString& name, double value);

private:
  struct Row {
    ParameterDescription description;
    QSlider* slider = nullptr;
    QDoubleSpinBox* spin = nullptr;
    QComboBox* combo = nullptr;
    QCheckBox* check = nullptr;
    bool logarithmic = false;
    /// The values a logarithmic slider spans (the spin box takes the whole range).
    double low = 0, high = 0;
  };
  void addRow(QGridLayout* grid, int line, const ParameterDescription& d);
  void emitChanged(const std::string& name, double value);
  int toSlider(const Row& row, double value) const;
  double fromSlider(const Row& row, int position) const;
  std::map<std::string, Row> rows_;
  std::map<std::string, QGroupBox*> groups_;
  bool quiet_ = false;
};

}  // namespace parcelscope::gui
