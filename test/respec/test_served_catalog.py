"""How a suite serves its robot systems to a GUI elsewhere (respec.robot.system.catalog_to_json):
what a client needs to rebuild each system, never the files' own text (issue 48, item 3)."""

import json
import shutil

from respec.robot import SystemCatalog
from respec.robot.system import ServedCatalog, catalog_to_json, robot_system

SECRET = 'operator pager: +1-555-0100'


def test_every_shipped_system_is_served_as_the_same_system_without_its_comments():
    catalog = SystemCatalog()
    text = catalog_to_json(catalog)
    served = ServedCatalog.from_json(text)
    assert served.names() == catalog.names()
    for name in catalog.names():
        original = catalog.load(name)
        assert served.load(name) == original, name   # the same abstraction or capability system
        assert served.load(name).sections == {key: value for key, value in original.sections.items()}
        for relative, file_text in original.files.items():
            comments = [line.strip() for line in file_text.splitlines() if line.strip().startswith('#')]
            assert comments == [] or comments[0] not in text, (name, relative)


def test_notes_and_other_keys_of_a_system_file_stay_on_the_server(tmp_path):
    shutil.copy('config/atlas.yaml', tmp_path / 'atlas_noted.yaml')
    with open(tmp_path / 'atlas_noted.yaml', 'a') as file:
        file.write(f'# {SECRET}\nnotes:\n  contact: "{SECRET}"\n')
    text = catalog_to_json(SystemCatalog(str(tmp_path)))
    assert SECRET not in text
    entry = next(e for e in json.loads(text)['systems'] if e['name'] == 'atlas_noted')
    assert list(entry['files']) == ['atlas_noted.yaml']
    served = ServedCatalog.from_json(text).load('atlas_noted')
    assert served == robot_system('atlas_noted', str(tmp_path)) and 'notes' not in served.sections


def test_a_catalog_tells_how_many_bytes_of_files_a_system_reads():
    from pathlib import Path

    from respec.robot import SystemCatalog

    config = Path(__file__).resolve().parents[2] / 'config'
    catalog = SystemCatalog()
    assert catalog.files_bytes('atlas') == (config / 'atlas.yaml').stat().st_size
    rover = sum(path.stat().st_size for path in [config / 'delivery_rover.yaml', *(config / 'delivery_rover').glob('*.yaml')])
    assert catalog.files_bytes('delivery_rover') == rover   # the system file and the three CNU files it names
    assert catalog.files_bytes('nowhere') == 0
