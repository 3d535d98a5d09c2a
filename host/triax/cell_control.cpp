#include "host/triax/cell_control.hpp"

#include "host/engine/cell_batch.hpp"
#include "host/triax/cell_boundary.hpp"

namespace dem {

namespace {

class SimulationCell final : public CellControl {
 public:
  explicit SimulationCell(Simulation& sim) : sim_(sim) {}
  // A stage that stops early (a blow-up) leaves no servo steering the cell.
  ~SimulationCell() override { sim_.end_cell_servo(); }
  std::array<Real, 3> lengths() const override { return cell_lengths(sim_); }
  Real length(int d) const override {
    return walled(sim_) ? cell_lengths(sim_)[static_cast<std::size_t>(d)] : sim_.axis_length(d);
  }
  Real volume() const override { return cell_volume(sim_); }
  std::array<Real, 3> stress() override { return cell_stress(sim_); }
  std::array<Real, 3> stiffness() override { return boundary_stiffness(sim_); }
  void set_rates(const Vec3& rate) override { set_cell_rates(sim_, rate); }
  bool servo_on_device(const CellServoSpec& spec) override {
    if (walled(sim_)) return false;
    sim_.set_cell_servo(spec);
    return true;
  }
  Vec3 rates() const override { return cell_rates(sim_); }
  Real dt() const override { return sim_.params().integ.dt; }
  long step_count() const override { return sim_.step_count(); }
  Real time() const override { return sim_.time(); }
  long touching() override { return sim_.touching()[0]; }
  Real unbalanced_ratio() override { return sim_.unbalanced_ratio(); }
  Real kinetic() override { return sim_.stats().kinetic; }
  int balls() const override { return sim_.particles().n; }

 private:
  Simulation& sim_;
};

class BatchCell final : public CellControl {
 public:
  BatchCell(CellBatch& batch, int s) : b_(batch), s_(s) {}
  std::array<Real, 3> lengths() const override {
    const Domain& d = b_.domain(s_);
    return {d.length(0), d.length(1), d.length(2)};
  }
  Real length(int d) const override { return b_.axis_length(s_, d); }
  Real volume() const override { return b_.domain(s_).volume(); }
  std::array<Real, 3> stress() override { return b_.contact_stress_diagonals()[static_cast<std::size_t>(s_)]; }
  std::array<Real, 3> stiffness() override { return b_.cell_stiffnesses()[static_cast<std::size_t>(s_)]; }
  void set_rates(const Vec3& rate) override { b_.set_strain_rate(s_, rate); }
  bool servo_on_device(const CellServoSpec& spec) override {
    b_.set_cell_servo(s_, spec);
    return true;
  }
  Vec3 rates() const override {
    const Real* r = b_.domain(s_).strain_rate;
    return Vec3(r[0], r[1], r[2]);
  }
  Real dt() const override { return b_.dt(s_); }
  long step_count() const override { return b_.step_count(s_); }
  Real time() const override { return b_.time(s_); }
  long touching() override { return b_.touching(s_); }
  Real unbalanced_ratio() override { return b_.unbalanced_ratio(s_); }
  Real kinetic() override { return b_.stats(s_).kinetic; }
  int balls() const override { return b_.balls(s_); }

 private:
  CellBatch& b_;
  int s_;
};

}  // namespace

std::unique_ptr<CellControl> cell_of(Simulation& sim) { return std::make_unique<SimulationCell>(sim); }
std::unique_ptr<CellControl> cell_of(CellBatch& batch, int s) { return std::make_unique<BatchCell>(batch, s); }

}  // namespace dem
