#pragma once
// The marching cubes case table and cell geometry live in framework/isosurface (shared with
// dual_contouring); marching_cubes uses them under its own namespace.

#include "isosurface/case_table.h"

namespace rtlab::isosurface::mc {

using tables::AmbiguityRule;
using tables::CaseTable;
using tables::CellEdge;
using tables::CellFace;
using tables::CellTriangulation;
using tables::decideJoinedFaces;
using tables::getCellEdges;
using tables::getCellFaces;
using tables::getCornerBit;
using tables::isFaceAmbiguous;
using tables::kCornerCount;
using tables::kEdgeCount;
using tables::kExtraVertex;
using tables::kFaceCount;
using tables::kMaxCellExtras;
using tables::kMaxCellTriangles;
using tables::triangulateCell;

} // namespace rtlab::isosurface::mc
