"""The record of the command line: the catalogue entry or files named, read with the reading
options (``shipblock.records.arguments``) and processed as ``--processing`` says."""

from __future__ import annotations

from pathlib import Path

from shipblock.cli._common import UserError


def _read_options(args) -> dict:
    from shipblock.records.arguments import read_options

    return read_options(args)


def _find_entry(record_id, catalogue):
    from shipblock.records.catalogue import load_catalogue

    entries = load_catalogue(catalogue)
    if record_id in entries:
        return entries[record_id]
    matches = [k for k in entries if k.endswith("/" + record_id) or k.split("/")[-1] == record_id]
    if len(matches) == 1:
        return entries[matches[0]]
    known = ", ".join(sorted(entries))
    raise UserError(f"record {record_id!r} is not in the catalogue; known records: {known}")


def _processing_chain(spec):
    from shipblock.processing import default_chain

    if spec in (None, "default"):
        return default_chain()
    if spec == "none":
        return []
    if spec == "demean":
        return [{"step": "demean"}]
    from shipblock.checks import toml_file

    path = Path(spec)
    if not path.exists():
        raise UserError(f"processing chain file {spec} does not exist")
    data = toml_file(path, "processing chain file")
    chain = data.get("processing")
    if isinstance(chain, dict):
        chain = chain.get("chain", chain.get("steps"))
    if not isinstance(chain, list):
        raise UserError(f"{spec}: expected a list of [[processing]] tables")
    return chain


def _load_motion(args):
    """The record of the command line, processed as --processing says."""
    return _processed(_read_record(args), args)


def _processed(motion, args):
    from shipblock.processing import process_motion

    chain = _processing_chain(args.processing)
    return process_motion(motion, chain) if chain else motion


def _read_record(args):
    """The record of the command line as read (converted to m/s^2, not processed)."""
    from shipblock.records.reading import read_motion

    if args.record and args.files:
        raise UserError("give either --record or record files, not both")
    if args.record:
        entry = _find_entry(args.record, args.catalogue)
        motion = entry.read(azimuth=args.azimuth, horizontal=args.horizontal,
                            **_read_options(args))
    elif args.files:
        import glob

        for f in args.files:
            if not Path(f).exists() and not glob.has_magic(f):
                raise UserError(f"{f}: no such file")
        motion = read_motion(args.files if len(args.files) > 1 else args.files[0],
                             azimuth=args.azimuth, horizontal=args.horizontal,
                             **_read_options(args))
    else:
        raise UserError("no record: give record files or --record ID (see 'shipblock info --help')")
    return motion


def _horizontal_line(motion) -> str:
    from shipblock.records.sensors import describe_horizontal

    return describe_horizontal(motion)
