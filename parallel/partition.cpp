#include "parallel/partition.hpp"

#include <stdexcept>
#include <string>

#ifdef SPH_MPI
#include <mpi.h>
#include <zoltan.h>
#endif

namespace sph::par {

#ifdef SPH_MPI
struct Partition::Zoltan {
  Zoltan_Struct* zz = nullptr;
  // The points of the current cut(), read by the callbacks.
  int dim = 0;
  const std::vector<double>* coords = nullptr;
  const std::vector<double>* weights = nullptr;
  ~Zoltan() {
    if (zz != nullptr) Zoltan_Destroy(&zz);
  }
};

namespace {

void zcheck(int code, const char* what) {
  if (code != ZOLTAN_OK && code != ZOLTAN_WARN) throw std::runtime_error(std::string("Zoltan: ") + what + " failed");
}

int num_obj(void* data, int* ierr) {
  const auto* z = static_cast<const Partition::Zoltan*>(data);
  *ierr = ZOLTAN_OK;
  return static_cast<int>(z->weights->size());
}

// Global ids: (rank, index) in two entries, unique without a global numbering; local ids: the index.
void obj_list(void* data, int /*num_gid*/, int /*num_lid*/, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int wgt_dim,
              float* wgts, int* ierr) {
  const auto* z = static_cast<const Partition::Zoltan*>(data);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::size_t n = z->weights->size();
  for (std::size_t k = 0; k < n; ++k) {
    gids[2 * k] = static_cast<ZOLTAN_ID_TYPE>(rank);
    gids[2 * k + 1] = static_cast<ZOLTAN_ID_TYPE>(k);
    lids[k] = static_cast<ZOLTAN_ID_TYPE>(k);
    if (wgt_dim > 0) wgts[k] = static_cast<float>((*z->weights)[k]);
  }
  *ierr = ZOLTAN_OK;
}

int num_geom(void* data, int* ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<const Partition::Zoltan*>(data)->dim;
}

void geom_multi(void* data, int /*num_gid*/, int /*num_lid*/, int num_obj, ZOLTAN_ID_PTR /*gids*/, ZOLTAN_ID_PTR lids,
                int num_dim, double* geom, int* ierr) {
  const auto* z = static_cast<const Partition::Zoltan*>(data);
  for (int k = 0; k < num_obj; ++k) {
    const auto at = static_cast<std::size_t>(lids[k]) * static_cast<std::size_t>(num_dim);
    for (int a = 0; a < num_dim; ++a) geom[k * num_dim + a] = (*z->coords)[at + static_cast<std::size_t>(a)];
  }
  *ierr = ZOLTAN_OK;
}

}  // namespace

Partition::Partition(const Comm& comm) : comm_(comm) {
  if (comm_.native() == nullptr) return;
  static const bool initialised = [] {
    float version = 0.0F;
    zcheck(Zoltan_Initialize(0, nullptr, &version), "initialise");
    return true;
  }();
  (void)initialised;
  zoltan_ = std::make_unique<Zoltan>();
  zoltan_->zz = Zoltan_Create(static_cast<MPI_Comm>(comm_.native()));
  if (zoltan_->zz == nullptr) throw std::runtime_error("Zoltan: create failed");
  Zoltan_Struct* zz = zoltan_->zz;
  // RCB with each object's weight; the cuts are kept for owner() (KEEP_CUTS); no import/export lists, since the
  // caller moves its particles itself by owner().
  for (const auto& [key, value] : {std::pair{"DEBUG_LEVEL", "0"}, {"LB_METHOD", "RCB"}, {"NUM_GID_ENTRIES", "2"},
                                   {"NUM_LID_ENTRIES", "1"}, {"OBJ_WEIGHT_DIM", "1"}, {"RETURN_LISTS", "NONE"},
                                   {"KEEP_CUTS", "1"}, {"RCB_REUSE", "0"}, {"IMBALANCE_TOL", "1.02"}}) {
    zcheck(Zoltan_Set_Param(zz, key, value), key);
  }
  Zoltan_Set_Num_Obj_Fn(zz, num_obj, zoltan_.get());
  Zoltan_Set_Obj_List_Fn(zz, obj_list, zoltan_.get());
  Zoltan_Set_Num_Geom_Fn(zz, num_geom, zoltan_.get());
  Zoltan_Set_Geom_Multi_Fn(zz, geom_multi, zoltan_.get());
}

void Partition::cut(int dim, const std::vector<double>& coords, const std::vector<double>& weights) {
  if (!zoltan_) {
    cut_ = true;
    return;
  }
  zoltan_->dim = dim;
  zoltan_->coords = &coords;
  zoltan_->weights = &weights;
  int changes = 0, num_gid = 0, num_lid = 0, num_import = 0, num_export = 0;
  ZOLTAN_ID_PTR import_gids = nullptr, import_lids = nullptr, export_gids = nullptr, export_lids = nullptr;
  int *import_procs = nullptr, *import_parts = nullptr, *export_procs = nullptr, *export_parts = nullptr;
  zcheck(Zoltan_LB_Partition(zoltan_->zz, &changes, &num_gid, &num_lid, &num_import, &import_gids, &import_lids,
                             &import_procs, &import_parts, &num_export, &export_gids, &export_lids, &export_procs,
                             &export_parts),
         "partition");
  Zoltan_LB_Free_Part(&import_gids, &import_lids, &import_procs, &import_parts);
  Zoltan_LB_Free_Part(&export_gids, &export_lids, &export_procs, &export_parts);
  zoltan_->coords = nullptr;
  zoltan_->weights = nullptr;
  cut_ = true;
}

int Partition::owner(const double* point) const {
  if (!zoltan_ || !cut_) return 0;
  int proc = 0;
  zcheck(Zoltan_LB_Point_Assign(zoltan_->zz, const_cast<double*>(point), &proc), "point assign");
  return proc;
}

#else

struct Partition::Zoltan {};
Partition::Partition(const Comm& comm) : comm_(comm) {}
void Partition::cut(int, const std::vector<double>&, const std::vector<double>&) { cut_ = true; }
int Partition::owner(const double*) const { return 0; }

#endif

Partition::~Partition() = default;

}  // namespace sph::par
