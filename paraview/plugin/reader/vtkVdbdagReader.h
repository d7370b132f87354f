// vtkVdbdagReader: reads an .ssvdag file (vdbdag's reader library) or a .vdb
// file (OpenVDB) as a vtkImageData, for ParaView (the VdbdagReader plugin)
// and for any VTK pipeline.
//
// The image covers a box of index coordinates (by default the union of the
// selected grids' active boxes) at a level of detail L: its points are the
// voxels box.min + n * 2^L, point-sampled, so reading costs what the image
// holds, not what the file holds (a 2048^3 grid at L = 3 reads 256^3
// voxels). The automatic level (LevelOfDetail -1) is the finest whose image
// stays within MaximumCells million points. Each selected grid becomes one
// point array named as the grid (3 components for vectors; a mask grid's
// active state as 0/1); inactive voxels hold what the file stores for them,
// so a level set keeps its inside sign and contours at 0. Origin, spacing and
// direction come from the grid's index-to-world transform (points at voxel
// centres, as OpenVDB's index space). Grids whose transform differs from the
// first selected grid's are left out with a warning.
//
// With OutputType 1 the output is instead the selected grids' active voxels
// and tiles in the same box as cells (a vtkMultiBlockDataSet of one
// vtkUnstructuredGrid per grid, ActiveCells.h), at full resolution, up to
// MaximumCells million cells per grid: what `vdbdag export` writes.
//
// With CompareWith set to a second file, each selected grid is compared with
// the grid of the same name there, as `vdbdag diff` does, over the union of
// both active boxes: arrays "a", "b", "abs_error" (|a - b|, the Euclidean
// norm of the difference for vectors) and "status" (0 the same bits and both
// active, 1 the value differs and both active, 2 active only in the first
// file, 3 only in the second, 4 inactive in both), prefixed "GRID " when
// several grids are compared.
#ifndef vtkVdbdagReader_h
#define vtkVdbdagReader_h

#include "vtkDataObjectAlgorithm.h"
#include "vtkVdbdagVolumeReaderModule.h"

#include <memory>

class vtkCallbackCommand;
class vtkDataArraySelection;

class VTKVDBDAGVOLUMEREADER_EXPORT vtkVdbdagReader : public vtkDataObjectAlgorithm
{
public:
  static vtkVdbdagReader* New();
  vtkTypeMacro(vtkVdbdagReader, vtkDataObjectAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  // 1 for an .ssvdag file (its magic) or a .vdb file (OpenVDB's magic).
  int CanReadFile(const char* name);

  // The grids to read (all by default), by name.
  vtkDataArraySelection* GetGridSelection();
  int GetNumberOfGridArrays();
  const char* GetGridArrayName(int index);
  int GetGridArrayStatus(const char* name);
  void SetGridArrayStatus(const char* name, int status);

  // Level of detail: the image's spacing is 2^L voxels; -1 (the default)
  // chooses the finest level within MaximumCells.
  vtkSetClampMacro(LevelOfDetail, int, -1, 30);
  vtkGetMacro(LevelOfDetail, int);
  // The automatic level's budget, in millions of points (default 64).
  vtkSetClampMacro(MaximumCells, double, 1e-6, 1e6);
  vtkGetMacro(MaximumCells, double);
  // A box of index coordinates (x0, x1, y0, y1, z0, z1, inclusive) instead
  // of the grids' active box, when UseBox is on.
  vtkSetMacro(UseBox, vtkTypeBool);
  vtkGetMacro(UseBox, vtkTypeBool);
  vtkBooleanMacro(UseBox, vtkTypeBool);
  vtkSetVector6Macro(Box, int);
  vtkGetVector6Macro(Box, int);
  // 0 (the default): the image; 1: the active voxels and tiles as cells.
  vtkSetClampMacro(OutputType, int, 0, 1);
  vtkGetMacro(OutputType, int);
  // A second file to compare with (empty: none).
  vtkSetStringMacro(CompareWith);
  vtkGetStringMacro(CompareWith);
  // The level the last update read (after RequestInformation).
  vtkGetMacro(ChosenLevel, int);

protected:
  vtkVdbdagReader();
  ~vtkVdbdagReader() override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkVdbdagReader(const vtkVdbdagReader&) = delete;
  void operator=(const vtkVdbdagReader&) = delete;
  static void SelectionModified(vtkObject*, unsigned long, void* clientdata, void*);
  int RequestImage(vtkInformation* outInfo);
  int RequestActiveCells(vtkInformation* outInfo);

  char* FileName = nullptr;
  char* CompareWith = nullptr;
  int LevelOfDetail = -1;
  int OutputType = 0;
  double MaximumCells = 64;
  vtkTypeBool UseBox = 0;
  int Box[6] = { 0, 0, 0, 0, 0, 0 };
  int ChosenLevel = 0;
  vtkDataArraySelection* GridSelection;
  vtkCallbackCommand* SelectionObserver;
  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
