import re

import numpy as np
import pytest

from softgym.design.controller import Controller
from softgym.design.material import Material, Palette, default_palette
from softgym.design.robot import RobotDesign, default_walker
from softgym.design.vxa import from_vxa, load_vxa, parse_vxa, save_vxa, to_vxa
from softgym.exceptions import InvalidDesignError


def material_xml(mid, name, E, cte, rgb=(0, 1, 1), density="1e+006", extra=""):
    r, g, b = rgb
    return f"""
        <Material ID="{mid}">
            <MatType>0</MatType>
            <Name>{name}</Name>
            <Display><Red>{r}</Red><Green>{g}</Green><Blue>{b}</Blue><Alpha>1</Alpha></Display>
            <Mechanical>
            <MatModel>0</MatModel>
            <Elastic_Mod>{E}</Elastic_Mod>
            <Plastic_Mod>0</Plastic_Mod>
            <Density>{density}</Density>
            <Poissons_Ratio>0.35</Poissons_Ratio>
            <CTE>{cte}</CTE>
            <uStatic>1</uStatic>
            <uDynamic>0.5</uDynamic>{extra}
            </Mechanical>
        </Material>"""


# A file laid out as evosoro's read_write_voxelyze.py writes it (3 x 2 x 2 voxels).
SEED_STYLE = (
    """<?xml version="1.0" encoding="ISO-8859-1"?>
        <VXA Version="1.0">
        <Simulator>
        <Integration><Integrator>0</Integrator><DtFrac>0.9</DtFrac></Integration>
        <StopCondition><StopConditionType>2</StopConditionType><StopConditionValue>5</StopConditionValue>
        <InitCmTime>1</InitCmTime></StopCondition>
        </Simulator>
        <Environment>
        <Thermal>
        <TempEnabled>1</TempEnabled>
        <TempAmp>38.7562021413</TempAmp>
        <TempBase>25</TempBase>
        <VaryTempEnabled>1</VaryTempEnabled>
        <TempPeriod>0.1</TempPeriod>
        </Thermal>
        <TimeBetweenTraces>0</TimeBetweenTraces>
        </Environment>
        <VXC Version="0.93">
        <Lattice><Lattice_Dim>0.01</Lattice_Dim></Lattice>
        <Palette>"""
    + material_xml(1, "Passive_Soft", "5000000.0", 0)
    + material_xml(2, "Passive_Hard", "500000000.0", 0, (0, 0, 1))
    + material_xml(3, "Active_+", "5000000.0", "0.0294016367221", (1, 0, 0))
    + material_xml(4, "Active_-", "5000000.0", "-0.0294016367221", (0, 1, 0))
    + """
        </Palette>
        <Structure Compression="ASCII_READABLE">
        <X_Voxels>3</X_Voxels>
        <Y_Voxels>2</Y_Voxels>
        <Z_Voxels>2</Z_Voxels>
<Data>
<Layer><![CDATA[123400]]></Layer>
<Layer><![CDATA[000003]]></Layer>
</Data>
</Structure>
        </VXC>
        </VXA>"""
)


def test_reads_a_seed_style_file():
    doc = parse_vxa(SEED_STYLE)
    d = doc.design
    assert d.shape == (3, 2, 2)
    # layer string index = x + X * y (x fastest), one layer per z
    assert d.grid[:, 0, 0].tolist() == [1, 2, 3]
    assert d.grid[:, 1, 0].tolist() == [4, 0, 0]
    assert d.grid[:, :, 1].T.ravel().tolist() == [0, 0, 0, 0, 0, 3]
    assert d.controller.temp_amplitude == pytest.approx(13.7562021413)
    assert d.controller.period == 0.1
    assert d.controller.muscle_cte == 0.0294016367221
    assert d.palette[4].cte == -0.0294016367221
    assert d.palette[2].youngs_modulus == 5e8 and d.palette[2].density == 1e6
    assert d.palette[2].color == (0.0, 0.0, 1.0, 1.0)
    assert doc.voxel_size == 0.01
    assert doc.settings["StopConditionValue"] == "5" and doc.settings["InitCmTime"] == "1"
    # bytes with the encoding declaration
    assert from_vxa(SEED_STYLE.encode("latin-1")) == d


def test_export_import_roundtrip_is_exact(tmp_path):
    pal = default_palette().with_changes(8, density=654321.123, cte=0.0312345).with_counterphase()
    pal = pal.with_changes(6, youngs_modulus=7654321.5)
    grid = default_walker().grid.copy()
    grid[0, 0, 4:6] = [8, 9]
    grid[5, 5, 4] = 6
    for ctrl in (Controller(), Controller(14.123456789123, 0.0123456789, 0.0399999)):
        d = RobotDesign(grid, palette=pal, controller=ctrl)
        assert from_vxa(to_vxa(d)) == d
    save_vxa(d, tmp_path / "robot.vxa", voxel_size=0.02, time_between_traces=0.5)
    assert load_vxa(tmp_path / "robot.vxa") == d
    doc = parse_vxa((tmp_path / "robot.vxa").read_bytes())
    assert doc.voxel_size == 0.02 and doc.settings["SaveTraces"] == "1"


def test_export_writes_the_seed_conventions():
    text = to_vxa(default_walker())
    assert "<TempAmp>39</TempAmp>" in text and "<TempBase>25</TempBase>" in text
    assert "<TempPeriod>0.25</TempPeriod>" in text
    assert '<Structure Compression="ASCII_READABLE">' in text
    assert "<Layer><![CDATA[111111111111111111111111111111111111]]></Layer>" in text
    assert re.search(r'<Material ID="3">.*?<CTE>0.01</CTE>', text, re.S)
    assert re.search(r'<Material ID="4">.*?<CTE>-0.01</CTE>', text, re.S)
    assert text.count("<Layer>") == 6


def test_ids_above_nine_roundtrip():
    pal = Palette(
        {
            1: Material("a", 5e6),
            12: Material("b<&>", 6e6),
            45: Material("c", 7e6),
            14: Material("d", 8e6),
        }
    )
    g = np.ones((3, 1, 1), dtype=np.int8)
    g[:, 0, 0] = [45, 45, 14]  # characters ']]>' must not break the file
    g2 = np.concatenate([g, np.full((3, 1, 1), 12, dtype=np.int8)], axis=2)
    d = RobotDesign(g2, palette=pal)
    assert from_vxa(to_vxa(d)) == d


def replace(pattern, repl, count=1):
    return re.sub(pattern, repl, SEED_STYLE, count=count, flags=re.S)


@pytest.mark.parametrize(
    "text, needle",
    [
        ("<VXA><VXC>", "malformed VXA XML"),
        ("<Robot/>", "root element is <Robot>"),
        (replace(r"<Palette>.*</Palette>", ""), "no <Palette> element"),
        (replace(r"<Structure.*</Structure>", ""), "no <Structure> element"),
        (
            replace(r"123400", "12340"),
            "<Layer> 0 of <Data> has 5 characters, expected X_Voxels\\*Y_Voxels = 6",
        ),
        (
            replace(r"<Layer><!\[CDATA\[000003\]\]></Layer>", ""),
            "1 <Layer> elements, <Z_Voxels> says 2",
        ),
        (replace(r"123400", "12#400"), "invalid material character '#' at position 2"),
        (replace(r"123400", "123700"), r"uses material ids \[7\]"),
        (
            replace(r"<Z_Voxels>2</Z_Voxels>", "<Z_Voxels>two</Z_Voxels>"),
            "<Z_Voxels> of <Structure> is not a number",
        ),
        (replace(r"<X_Voxels>3</X_Voxels>", ""), "missing <X_Voxels>"),
        (replace(r'Compression="ASCII_READABLE"', 'Compression="ZLIB"'), 'Compression="ZLIB"'),
        (
            replace(r"<Elastic_Mod>5000000.0</Elastic_Mod>", "<Elastic_Mod>soft</Elastic_Mod>"),
            '<Elastic_Mod> of <Material ID="1"> is not a number',
        ),
        (
            replace(r"<Density>1e\+006</Density>", "<Density>-5</Density>"),
            '<Material ID="1">: .*density must lie in',
        ),
        (replace(r"<MatModel>0</MatModel>", "<MatModel>1</MatModel>"), "only linear materials"),
        (replace(r'<Material ID="2">', '<Material ID="1">'), 'defines <Material ID="1"> twice'),
        (replace(r'<Material ID="2">', "<Material>"), "missing or non-integer ID"),
        (
            replace(r"<TempPeriod>0.1</TempPeriod>", "<TempPeriod>0.001</TempPeriod>"),
            "<Thermal> settings .*period = 0.001",
        ),
        (replace(r"<TempAmp>38.7562021413</TempAmp>", ""), "missing <TempAmp> of <Thermal>"),
        (
            replace(r"<Lattice_Dim>0.01</Lattice_Dim>", "<Lattice_Dim>0</Lattice_Dim>"),
            "<Lattice_Dim> must be > 0",
        ),
    ],
)
def test_malformed_files_name_the_offending_element(text, needle):
    with pytest.raises(InvalidDesignError, match=needle):
        parse_vxa(text)


def test_missing_optional_parts_use_seed_defaults():
    text = replace(r"<Environment>.*</Environment>", "")
    text = re.sub(r"<uStatic>1</uStatic>", "", text)
    d = from_vxa(text)
    assert d.controller.temp_amplitude == 14.0 and d.controller.period == 0.25
    assert d.palette[1].mu_static == 1.0


def test_to_vxa_writes_a_terrain_as_the_seeds_fixed_obstacle_voxels():
    # the seed's fence: 44 Obstacle voxels (id 5) around the robot, four fixed
    # regions; the oracle gives this file the same numbers as the seed's own
    # 50x50 obstacle workspace (checked when it was written)
    import re

    import numpy as np
    import pytest

    from softgym.design import default_walker
    from softgym.design.vxa import parse_vxa, to_vxa
    from softgym.exceptions import InvalidTerrainError
    from softgym.terrain import Box, Terrain

    walker = default_walker()
    fence = Terrain.fence(center=(3, 3))
    text = to_vxa(walker, terrain=fence)
    layers = re.findall(r"<Layer><!\[CDATA\[(.*?)\]\]></Layer>", text) or re.findall(r"<Layer>(.*?)</Layer>", text)
    assert len(layers) == 6 and len(layers[0]) == 12 * 12  # the widened lattice
    assert sum(layer.count("5") for layer in layers) == 44
    assert text.count("<DofFixed>63</DofFixed>") == 4
    # import takes the fixed voxels back out of the robot, as the same boxes
    doc = parse_vxa(text)
    np.testing.assert_array_equal(doc.design.grid, walker.grid)
    assert doc.terrain is not None
    assert sorted((b.lo, b.hi) for b in doc.terrain.boxes) == sorted((b.lo, b.hi) for b in fence.boxes)
    assert parse_vxa(to_vxa(walker)).terrain is None
    assert to_vxa(walker, terrain=Terrain.flat()) == to_vxa(walker)
    with pytest.raises(InvalidTerrainError, match="off the lattice"):
        to_vxa(walker, terrain=Terrain.from_boxes([Box((7.5, 0, 0), (9, 6, 1))]))
    with pytest.raises(InvalidTerrainError, match="overlaps the robot"):
        to_vxa(walker, terrain=Terrain.from_boxes([Box((5, 0, 0), (9, 6, 1))]))
    assert re.search(r"<NumBCs>4</NumBCs>", text)


def test_the_seeds_own_obstacle_workspace_reads_as_robot_plus_fence():
    # the seed's obstacle runs (the seed study): a 50x50x6 lattice, the robot at
    # voxel (22, 22, 0), 44 wall voxels of material 5 fixed by four regions
    import numpy as np

    from softgym.design import default_walker
    from softgym.design.vxa import parse_vxa, to_vxa
    from softgym.terrain import Terrain

    walker = default_walker()
    small = to_vxa(walker, terrain=Terrain.fence(center=(3, 3)))
    doc = parse_vxa(small)
    big = np.zeros((50, 50, 6), dtype=np.int8)
    big[22:28, 22:28, :] = walker.grid
    wall = np.zeros((50, 50, 6), dtype=bool)
    wall[19:31, 19:31, 0] = True
    wall[20:30, 20:30, 0] = False
    big[wall] = 5
    layers = "".join(
        "<Layer>" + "".join(str(int(v)) for v in big[:, :, z].T.ravel()) + "</Layer>" for z in range(6)
    )
    regions = [(19, 19, 12, 1), (19, 30, 12, 1), (19, 20, 1, 10), (30, 20, 1, 10)]
    bcs = "".join(
        f"<FRegion><PrimType>0</PrimType><X>{x / 50}</X><Y>{y / 50}</Y><Z>0</Z><dX>{dx / 50}</dX>"
        f"<dY>{dy / 50}</dY><dZ>{1 / 6}</dZ><DofFixed>63</DofFixed></FRegion>"
        for x, y, dx, dy in regions
    )
    text = re.sub(r"<X_Voxels>\d+</X_Voxels>", "<X_Voxels>50</X_Voxels>", small)
    text = re.sub(r"<Y_Voxels>\d+</Y_Voxels>", "<Y_Voxels>50</Y_Voxels>", text)
    text = re.sub(r"<Data>.*</Data>", f"<Data>{layers}</Data>", text, flags=re.S)
    text = re.sub(r"<Boundary_Conditions>.*</Boundary_Conditions>",
                  f"<Boundary_Conditions><NumBCs>4</NumBCs>{bcs}</Boundary_Conditions>", text, flags=re.S)
    seed = parse_vxa(text)
    np.testing.assert_array_equal(seed.design.grid, walker.grid)
    assert sorted((b.lo, b.hi) for b in seed.terrain.boxes) == sorted((b.lo, b.hi) for b in doc.terrain.boxes)
    assert sum(np.prod(b.size) for b in seed.terrain.boxes) == 44
