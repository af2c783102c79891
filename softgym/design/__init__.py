"""Robot designs: materials, controllers, voxel grids, CPPN genomes, ``.vxa`` files.

The layer between genomes and the engine: a :class:`RobotDesign` is plain
data (an int8 grid of material ids, a :class:`Palette`, a :class:`Controller`)
and :meth:`RobotDesign.to_body` hands it to the engine. Material ids are the
seed study's (1-4 evosoro's, 5 obstacle, 6-9 evolvable), see
:mod:`softgym.design.material`.
"""

from softgym.design.controller import CONTROLLER_BOUNDS, Controller
from softgym.design.cppn import (
    ACTIVATIONS,
    CPPN,
    HIDDEN_ACTIVATIONS,
    INPUT_NAMES,
    MATERIAL_TREE_4,
    MATERIAL_TREE_8,
    MUTATIONS,
    MutationResult,
    cppn_inputs,
    material_tree,
)
from softgym.design.material import (
    BONE_IDS,
    EVOLVABLE_BOUNDS,
    MAX_ABS_CTE,
    MUSCLE_IDS,
    OBSTACLE_IDS,
    OLD_MATERIAL_IDS,
    TISSUE_IDS,
    Material,
    MaterialBounds,
    Palette,
    default_palette,
    seed_materials,
)
from softgym.design.robot import (
    DESIGN_SCHEMA,
    DESIGN_VERSION,
    MAX_DESIGN_JSON_BYTES,
    MAX_GRID_DIM,
    MAX_GRID_VOXELS,
    CompositionRules,
    RobotDesign,
    check_grid_shape,
    default_walker,
    label_components,
    largest_component_mask,
)
from softgym.design.vxa import (
    MAX_VXA_BYTES,
    VxaDocument,
    from_vxa,
    load_vxa,
    parse_vxa,
    save_vxa,
    to_vxa,
)

__all__ = [
    "ACTIVATIONS",
    "BONE_IDS",
    "CONTROLLER_BOUNDS",
    "CPPN",
    "DESIGN_SCHEMA",
    "DESIGN_VERSION",
    "EVOLVABLE_BOUNDS",
    "HIDDEN_ACTIVATIONS",
    "INPUT_NAMES",
    "MATERIAL_TREE_4",
    "MATERIAL_TREE_8",
    "MAX_ABS_CTE",
    "MAX_DESIGN_JSON_BYTES",
    "MAX_GRID_DIM",
    "MAX_GRID_VOXELS",
    "MAX_VXA_BYTES",
    "MUSCLE_IDS",
    "MUTATIONS",
    "OBSTACLE_IDS",
    "OLD_MATERIAL_IDS",
    "TISSUE_IDS",
    "CompositionRules",
    "Controller",
    "Material",
    "MaterialBounds",
    "MutationResult",
    "Palette",
    "RobotDesign",
    "VxaDocument",
    "check_grid_shape",
    "cppn_inputs",
    "default_palette",
    "default_walker",
    "from_vxa",
    "label_components",
    "largest_component_mask",
    "load_vxa",
    "material_tree",
    "parse_vxa",
    "save_vxa",
    "seed_materials",
    "to_vxa",
]
