"""Walker parameters and controller memory by name (walkers/common/slots.py): each layout is
declared once, its fields tile the array, and the tables, memories and labels follow it."""
import numpy as np
import pytest

from walkers.common.slots import label_slots, param_slots, read, size, slots
from walkers.quadruped import controller as quadruped
from walkers.quadruped.params import FIELD as QUADRUPED_FIELD, QuadrupedParams
from walkers.ranger import rollout as ranger_rollout, tables as ranger
from walkers.simbicon import controller as simbicon
from walkers.simple_biped import controller as biped, rollout as biped_rollout
from walkers.simple_biped.params import FIELD as BIPED_FIELD, SimpleBipedParams

LAYOUTS = [biped.MEM, biped.ROW, BIPED_FIELD, quadruped.MEM, QUADRUPED_FIELD, simbicon.MEM,
           ranger.MEM, ranger.CONST, ranger.PC, ranger.LOG]


@pytest.mark.parametrize("layout", LAYOUTS, ids=lambda x: type(x).__name__)
def test_fields_tile_the_array_without_overlap(layout):
    sizes = type(layout).SIZES
    owner = np.full(size(layout), -1)
    for k, name in enumerate(layout._fields):
        start = getattr(layout, name)
        assert (owner[start:start + sizes[name]] == -1).all(), name
        owner[start:start + sizes[name]] = k
    assert (owner >= 0).all()


@pytest.mark.parametrize("cls, layout", [(SimpleBipedParams, BIPED_FIELD),
                                         (QuadrupedParams, QUADRUPED_FIELD)])
def test_parameter_slots_read_the_fields_of_to_array(cls, layout):
    p = cls()
    table = p.to_array()
    assert len(table) == size(layout)
    for name in layout._fields:
        assert table[getattr(layout, name)] == float(getattr(p, name)), name


def test_memories_and_tables_have_their_layouts_size():
    assert len(biped_rollout.Run(gait="walk").memory) == size(biped.MEM)
    assert len(ranger.make_memory()) == size(ranger.MEM)
    assert len(simbicon.make_memory()) == size(simbicon.MEM)
    tables = ranger.make_tables(ranger.RangerParams(), 1e-3, max_steps=4)
    assert len(tables.k) == size(ranger.CONST) and tables.prog.shape[1] == size(ranger.PC)
    assert tables.steplog.shape[1] == size(ranger.LOG)
    assert size(quadruped.MEM) == quadruped.N_MEMORY


def test_labels_come_from_the_memory_layout():
    mem = np.arange(size(biped.MEM), dtype=float)
    assert [mem[k] for k in biped_rollout.LABEL_SLOTS] == [
        mem[getattr(biped.MEM, n)] for n in biped_rollout.LABELS]
    assert read(mem, biped.MEM, ["gait", "state"]) == {"gait": biped.MEM.gait, "state": biped.MEM.state}
    assert list(ranger_rollout.LABEL_INDEX[:5]) == [
        ranger.MEM.gait, ranger.MEM.phase, ranger.MEM.stance, ranger.MEM.raw, ranger.MEM.raw + 1]


def test_bad_declarations_and_labels_are_named():
    with pytest.raises(ValueError, match="declared twice"):
        slots("Twice", ("a", "b", "a"))
    with pytest.raises(ValueError, match="Bad.b: size 0"):
        slots("Bad", ("a", ("b", 0, "empty")))
    layout = slots("L", ("a", ("b", 2, "two")))
    with pytest.raises(ValueError, match="b:2: b has 2 slot"):
        label_slots(layout, ["b:2"])
    assert param_slots(SimpleBipedParams).hip_mass == 0
