#include <algorithm>
#include <chrono>

#include "engine/vof/error.hpp"
#include "engine/vof/linear/petsc.hpp"

namespace runout::engine::vof {

PressureSolver::~PressureSolver() {
  if (ksp_) KSPDestroy(&ksp_);
  if (Apin_) MatDestroy(&Apin_);
  if (Apc_) MatDestroy(&Apc_);
  if (Apc_first_) MatDestroy(&Apc_first_);
  if (A_) MatDestroy(&A_);
  for (::Vec* v : {&x_, &b_, &r_, &dx_})
    if (*v) VecDestroy(v);
}

void PressureSolver::make_ksp() {
  if (ksp_) KSPDestroy(&ksp_);
  petsc_check(KSPCreate(ranks_.comm().comm, &ksp_), "KSPCreate");
  petsc_check(KSPSetType(ksp_, KSPCG), "KSPSetType");
  PC pc;
  petsc_check(KSPGetPC(ksp_, &pc), "KSPGetPC");
  if (cfg_.pressure_pc == "gamg") {
    petsc_check(PCSetType(pc, PCGAMG), "PCSetType gamg");
    // The 1/A of the two phases differ a thousandfold: GAMG's default Chebyshev smoothers, with their
    // estimated eigenvalue bounds, then made the preconditioner indefinite for CG now and then.
    // Damped Jacobi smoothing (Richardson, scale 0.6) is symmetric and stays positive definite.
    // (Defaults only: a user's PETSc options with the same names are kept.)
    for (const auto& [name, value] : {std::pair<const char*, const char*>{"-runout_p_mg_levels_ksp_type", "richardson"},
                                      {"-runout_p_mg_levels_pc_type", "jacobi"},
                                      {"-runout_p_mg_levels_ksp_richardson_scale", "0.6"},
                                      {"-runout_p_mg_levels_ksp_max_it", "2"}}) {
      PetscBool set = PETSC_FALSE;
      PetscOptionsHasName(nullptr, nullptr, name, &set);
      if (!set) PetscOptionsSetValue(nullptr, name, value);
    }
  } else if (cfg_.pressure_pc == "ilu") {
    // ILU(0) over the region's rows: on terrain-following meshes, whose thin layers couple each
    // column about 10^4 times more strongly than the columns to each other, CG takes half GAMG's
    // iterations, each solve about a ninth of the time (docs/design/vof.md).
    // Over ranks, block Jacobi with ILU(0) in each rank's block (PETSc's defaults for the blocks): a
    // column mesh split by whole columns keeps each column's coupling inside a block.
    petsc_check(PCSetType(pc, ranks_.distributed() ? PCBJACOBI : PCILU), "PCSetType ilu");
  } else if (cfg_.pressure_pc == "hypre") {
    if (PCSetType(pc, PCHYPRE)) throw VofError("pressure_pc: this PETSc has no hypre (valid here: gamg)");
    petsc_check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
  } else {
    throw VofError("pressure_pc: unknown '" + cfg_.pressure_pc + "' (valid: gamg, hypre, ilu)");
  }
  petsc_check(KSPSetTolerances(ksp_, cfg_.pressure_rtol, 1e-300, PETSC_DEFAULT, 2000), "KSPSetTolerances");
  petsc_check(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
  // PETSc options with the prefix runout_p_ (PETSC_OPTIONS) set the preconditioner's details; the
  // relative tolerances are set again for each solve (VofConfig::pressure_rtol*).
  petsc_check(KSPSetOptionsPrefix(ksp_, "runout_p_"), "KSPSetOptionsPrefix");
  petsc_check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
}

void PressureSolver::make_system(int rows, int first_row, long long total, const std::vector<int>& own_nnz, const std::vector<int>& off_nnz) {
  if (A_) MatDestroy(&A_);
  if (Apin_) MatDestroy(&Apin_);
  if (Apc_) MatDestroy(&Apc_);
  if (Apc_first_) MatDestroy(&Apc_first_);
  pc_builds_ = 0;
  for (::Vec* v : {&x_, &b_, &r_, &dx_})
    if (*v) VecDestroy(v);
  n_ = rows;
  first_row_ = first_row;
  const std::vector<PetscInt> nz(own_nnz.begin(), own_nnz.end()), oz(off_nnz.begin(), off_nnz.end());
  if (!ranks_.distributed()) {
    petsc_check(MatCreateSeqAIJ(PETSC_COMM_SELF, n_, n_, 0, nz.data(), &A_), "MatCreateSeqAIJ");
    petsc_check(VecCreateSeq(PETSC_COMM_SELF, n_, &x_), "VecCreateSeq");
  } else {
    const MPI_Comm comm = ranks_.comm().comm;
    const auto N = PetscInt(total);
    petsc_check(MatCreateAIJ(comm, n_, n_, N, N, 0, nz.data(), 0, oz.data(), &A_), "MatCreateAIJ");
    petsc_check(VecCreateMPI(comm, n_, N, &x_), "VecCreateMPI");
  }
  petsc_check(MatSetOption(A_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
  petsc_check(VecDuplicate(x_, &b_), "VecDuplicate");
  petsc_check(VecDuplicate(x_, &r_), "VecDuplicate");
  petsc_check(VecDuplicate(x_, &dx_), "VecDuplicate");
  make_ksp();
  system_fresh_ = true;
}

void PressureSolver::set_tolerance(bool final) {
  petsc_check(KSPSetTolerances(ksp_, final ? cfg_.pressure_rtol : cfg_.pressure_rtol_intermediate, 1e-300, PETSC_DEFAULT, 2000),
              "KSPSetTolerances");
}

void PressureSolver::begin_matrix(bool reuse) {
  if (!reuse) petsc_check(MatZeroEntries(A_), "MatZeroEntries");
}

void PressureSolver::set_entry(PetscInt i, PetscInt j, double value) {
  const PetscScalar v = value;
  petsc_check(MatSetValues(A_, 1, &i, 1, &j, &v, INSERT_VALUES), "MatSetValues");
}

void PressureSolver::set_rows(const std::vector<double>& diag, const std::vector<double>& rhs, const std::vector<double>& x0, bool reuse) {
  PetscScalar *bv, *xv;
  petsc_check(VecGetArray(b_, &bv), "VecGetArray");
  petsc_check(VecGetArray(x_, &xv), "VecGetArray");
  for (int k = 0; k < n_; ++k) {
    if (!reuse) {
      const PetscInt r0 = first_row_ + k;
      const PetscScalar v = diag[k];
      petsc_check(MatSetValues(A_, 1, &r0, 1, &r0, &v, INSERT_VALUES), "MatSetValues");
    }
    bv[k] = rhs[k];
    xv[k] = x0[k];
  }
  VecRestoreArray(b_, &bv);
  VecRestoreArray(x_, &xv);
  if (!reuse) {
    petsc_check(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY), "MatAssembly");
    petsc_check(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY), "MatAssembly");
  }
}

void PressureSolver::timed_solve(Mat Ap) {
  petsc_check(KSPSetOperators(ksp_, Ap, Ap), "KSPSetOperators");
  const auto t_ksp = std::chrono::steady_clock::now();
  petsc_check(KSPSolve(ksp_, r_, dx_), "KSPSolve");
  ksp_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_ksp).count();
}

int PressureSolver::solve(const Solve& s, double t) {
  PetscInt its = 0;
  for (int pass = 0; pass < (s.initial ? 3 : 1); ++pass) {
    petsc_check(MatMult(A_, x_, r_), "MatMult");
    petsc_check(VecAYPX(r_, -1.0, b_), "VecAYPX");  // r = b - A x
    petsc_check(VecSet(dx_, 0.0), "VecSet");
    const bool same = (s.reuse || pass > 0) && !system_fresh_;  // passes of the initial solve share the matrix too
    // The preconditioner is rebuilt every pressure_pc_refresh steps (GAMG: the coarse operators
    // from the current matrix, with the prolongators of the solver's first build) and made anew
    // whenever the active region changes; in between, the last one preconditions the new matrix
    // (still symmetric positive definite).
    bool keep_pc = same;
    // (Counted per step: the outer correctors after a step's first keep it.)
    if (!same && !s.initial && !system_fresh_) keep_pc = later_outer || ++steps_since_pc_ < std::max(1, cfg_.pressure_pc_refresh);
    if (!keep_pc) steps_since_pc_ = 0;
    Mat Ap = A_;
    if (s.closed) {
      // A closed domain: the correction is fixed to zero in row 0 (its row and column replaced by
      // the diagonal), which leaves a nonsingular system with the same solution up to the
      // constant that the pressure level takes care of.
      if (!same) {
        if (Apin_) petsc_check(MatCopy(A_, Apin_, SAME_NONZERO_PATTERN), "MatCopy");
        else petsc_check(MatDuplicate(A_, MAT_COPY_VALUES, &Apin_), "MatDuplicate");
        const PetscInt row0 = 0;  // the whole system's first row: rank 0's
        const PetscInt n0 = ranks_.comm().rank == 0 ? 1 : 0;
        petsc_check(MatZeroRowsColumns(Apin_, n0, &row0, s.diag0, dx_, r_), "MatZeroRowsColumns");
      } else {
        if (ranks_.comm().rank == 0) petsc_check(VecSetValue(r_, 0, 0.0, INSERT_VALUES), "VecSetValue");  // dx_0 = 0
        VecAssemblyBegin(r_);
        VecAssemblyEnd(r_);
      }
      Ap = Apin_;
    }
    system_fresh_ = false;
    petsc_check(KSPSetReusePreconditioner(ksp_, keep_pc ? PETSC_TRUE : PETSC_FALSE), "KSPSetReusePreconditioner");
    timed_solve(Ap);
    if (!keep_pc) remember_pc(Ap);
    KSPConvergedReason reason;
    KSPGetConvergedReason(ksp_, &reason);
    PetscInt k = 0;
    KSPGetIterationNumber(ksp_, &k);
    its += k;
    if (reason < 0 && keep_pc) {
      // The kept preconditioner no longer fits the matrix (the viscosity changed by orders of
      // magnitude somewhere): build it anew and solve again.
      petsc_check(VecSet(dx_, 0.0), "VecSet");
      petsc_check(KSPSetReusePreconditioner(ksp_, PETSC_FALSE), "KSPSetReusePreconditioner");
      timed_solve(Ap);
      remember_pc(Ap);
      KSPGetConvergedReason(ksp_, &reason);
      KSPGetIterationNumber(ksp_, &k);
      its += k;
      steps_since_pc_ = 0;
    }
    if (reason < 0)
      throw VofError("pressure solver (CG + " + cfg_.pressure_pc + ") did not converge at t = " + std::to_string(t) + " s: reason " +
                     std::to_string(int(reason)) + " after " + std::to_string(int(k)) + " iterations");
    petsc_check(VecAXPY(x_, 1.0, dx_), "VecAXPY");
  }
  return int(its);
}

void PressureSolver::solution(std::vector<double>& x) const {
  const PetscScalar* xv;
  VecGetArrayRead(x_, &xv);
  x.assign(xv, xv + n_);
  VecRestoreArrayRead(x_, &xv);
}

void PressureSolver::shift(double s) {
  const PetscScalar shift = s;
  VecShift(x_, shift);
}

// Keep copies of the operators the preconditioner was built from: the first build of this
// system's solver and the latest. PETSc's GAMG keeps the prolongators of its first build and later
// builds only form the coarse operators anew (Galerkin), so the preconditioner in use depends on
// both.
void PressureSolver::remember_pc(Mat Ap) {
  if (!Apc_first_) petsc_check(MatDuplicate(Ap, MAT_COPY_VALUES, &Apc_first_), "MatDuplicate");
  if (Apc_) MatDestroy(&Apc_);
  petsc_check(MatDuplicate(Ap, MAT_COPY_VALUES, &Apc_), "MatDuplicate");
  ++pc_builds_;
}

void PressureSolver::save_pc(VofState& st, const PcColumns& cols) const {
  st.steps_since_pc = steps_since_pc_;
  st.pc_builds = pc_builds_ > 1 ? 2 : pc_builds_;
  st.pc_rows.clear();
  st.pc_cols.clear();
  st.pc_first_values.clear();
  st.pc_values.clear();
  if (!Apc_) return;
  st.pc_rows.push_back(0);
  for (PetscInt i = first_row_; i < first_row_ + n_; ++i) {  // this rank's rows
    PetscInt nc1 = 0, nc0 = 0;
    const PetscInt *c1 = nullptr, *c0 = nullptr;
    const PetscScalar *v1 = nullptr, *v0 = nullptr;
    petsc_check(MatGetRow(Apc_, i, &nc1, &c1, &v1), "MatGetRow");
    petsc_check(MatGetRow(Apc_first_, i, &nc0, &c0, &v0), "MatGetRow");
    const bool same = nc0 == nc1 && std::equal(c0, c0 + nc0, c1);
    for (PetscInt k = 0; same && k < nc1; ++k) {
      st.pc_cols.push_back(cols.stored ? cols.stored(c1[k]) : int(c1[k]));
      st.pc_values.push_back(double(v1[k]));
      st.pc_first_values.push_back(double(v0[k]));
    }
    petsc_check(MatRestoreRow(Apc_first_, i, &nc0, &c0, &v0), "MatRestoreRow");
    petsc_check(MatRestoreRow(Apc_, i, &nc1, &c1, &v1), "MatRestoreRow");
    if (!same) throw VofError("state: the pressure preconditioner's operators differ in structure");
    st.pc_rows.push_back(int(st.pc_cols.size()));
  }
}

// Set the operator's values from compressed rows (the structure the active region's system has)
// and assemble it.
void PressureSolver::set_operator(Mat M, const VofState& st, const std::vector<double>& values, const PcColumns& cols) {
  PetscInt total = 0;
  petsc_check(MatGetSize(M, &total, nullptr), "MatGetSize");
  for (int i = 0; i < n_; ++i) {
    const int k0 = st.pc_rows[i], k1 = st.pc_rows[std::size_t(i) + 1];
    if (k0 < 0 || k1 < k0 || std::size_t(k1) > st.pc_cols.size()) throw VofError("restore: the checkpoint's pressure operator is damaged");
    for (int k = k0; k < k1; ++k) {
      const PetscInt r0 = first_row_ + i, c0 = cols.system ? cols.system(st.pc_cols[k]) : PetscInt(st.pc_cols[k]);
      if (c0 < 0 || c0 >= total) throw VofError("restore: the checkpoint's pressure operator is damaged");
      const PetscScalar v = values[k];
      if (MatSetValues(M, 1, &r0, 1, &c0, &v, INSERT_VALUES))
        throw VofError("restore: the checkpoint's pressure operator does not fit the active region's system");
    }
  }
  petsc_check(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY), "MatAssembly");
  petsc_check(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY), "MatAssembly");
}

// The preconditioner is built from the operator of the solver's first build, then, if it was
// rebuilt since, from the latest one, and placed where that run had it (A, or Apin in a closed
// domain), so that the following steps, which reassemble the operator and keep or refresh the
// preconditioner, are that run's.
void PressureSolver::restore_pc(const VofState& st, bool closed, const PcColumns& cols) {
  steps_since_pc_ = st.steps_since_pc;
  if (st.pc_builds <= 0) return;  // none built yet: the system stays fresh
  if (st.pc_rows.size() != std::size_t(n_) + 1 || st.pc_cols.size() != st.pc_values.size() ||
      st.pc_first_values.size() != st.pc_values.size() || st.pc_rows.back() != int(st.pc_cols.size()))
    throw VofError("restore: the checkpoint's pressure operator does not match its active region");
  for (int build = 0; build < std::min(st.pc_builds, 2); ++build) {
    const auto& values = build == 0 ? st.pc_first_values : st.pc_values;
    Mat Ap = A_;
    if (closed) {
      if (!Apin_) {
        set_operator(A_, st, values, cols);
        petsc_check(MatDuplicate(A_, MAT_COPY_VALUES, &Apin_), "MatDuplicate");
      } else {
        set_operator(Apin_, st, values, cols);
      }
      Ap = Apin_;
    } else {
      set_operator(A_, st, values, cols);
    }
    petsc_check(KSPSetOperators(ksp_, Ap, Ap), "KSPSetOperators");
    petsc_check(KSPSetReusePreconditioner(ksp_, PETSC_FALSE), "KSPSetReusePreconditioner");
    petsc_check(KSPSetUp(ksp_), "KSPSetUp");  // what KSPSolve does before it iterates
    petsc_check(KSPSetUpOnBlocks(ksp_), "KSPSetUpOnBlocks");
    remember_pc(Ap);
  }
  pc_builds_ = st.pc_builds;
  system_fresh_ = false;
}

}  // namespace runout::engine::vof
