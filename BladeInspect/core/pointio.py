"""Measured point files: CSV with a header, and whitespace .xyz/.asc/.txt (docs/contracts.md).

Rows a sensor left without a reading ('nan', blank, garbage, a short row) are skipped and
counted, never fatal: one bad reading must not stop a batch. Everything that makes the whole
file unusable is an InputError "<path>: <problem>".
"""

import os
import re
import warnings
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError

MIN_POINTS = 10
# |coordinate| beyond which a number is not a measurement in millimetres but a corrupt field
# (an overflow, a misplaced exponent): a kilometre, three orders of magnitude past any
# inspection rig's travel, yet far enough that a scan in micrometres (a blade of 1e5 um)
# still reaches the unit check, which names the unit. A NaN (or an empty field) is a sensor's
# "no reading" and is skipped; an infinity or a huge finite number is an overflow or a field
# written wrong, and so may be the rest of the file: it is refused.
MAX_COORDINATE_MM = 1e6
SNR_RANGE = (0.0, 100.0)
CSV_EXTENSIONS = (".csv",)
WHITESPACE_EXTENSIONS = (".xyz", ".asc", ".txt")
FREECAD_EXTENSIONS = (".ply", ".pcd")


@dataclass
class PointSet:
    xyz: np.ndarray                               # (N,3) mm
    snr: np.ndarray = None                        # (N,) 0..100, or None: all points weigh 1
    columns: dict = field(default_factory=dict)   # extra columns, (N,) float or str arrays
    n_rows_skipped: int = 0                       # data rows without a usable x, y, z (, snr)
    source: str = ""                              # the file it came from


def read_points(path):
    """Read a .csv (header with x, y, z, optional snr and extra columns) or a whitespace
    .xyz/.asc/.txt (x y z [snr], '#' comments) file into a PointSet."""
    path = str(path)
    ext = os.path.splitext(path)[1].lower()
    if ext in FREECAD_EXTENSIONS:
        raise InputError("%s: %s point files are read through FreeCAD "
                         "(cad.load.read_points_any), not the plain-text reader" % (path, ext))
    if ext not in CSV_EXTENSIONS + WHITESPACE_EXTENSIONS:
        raise InputError("%s: unknown point file type '%s' (use .csv, .xyz, .asc, .txt, .ply "
                         "or .pcd)" % (path, ext))
    text = _read_text(path)
    if ext in CSV_EXTENSIONS:
        names, columns, skipped = _split_csv(path, text)
    else:
        names, columns, skipped = _split_whitespace(path, text)
    return _build(path, names, columns, skipped)


def _read_text(path):
    if not os.path.exists(path):
        raise InputError("%s: no such file" % path)
    if os.path.isdir(path):
        raise InputError("%s: is a folder, not a point file" % path)
    try:
        with open(path, "r", encoding="utf-8-sig") as fh:
            text = fh.read()
    except UnicodeDecodeError:
        raise InputError("%s: not a text file" % path)
    except OSError as exc:
        raise InputError("%s: cannot be read (%s)" % (path, exc.strerror or exc))
    if not text.strip():
        raise InputError("%s: the file is empty" % path)
    return text


def _split_csv(path, text):
    """Header names, each column's field strings, and the count of skipped rows (whose field
    count differs from the header's)."""
    header, body = _header_and_body(text)
    if header is None:
        raise InputError("%s: the file has only comments" % path)
    names = [n.strip().strip('"').strip("'").strip().lower() for n in header.split(",")]
    missing = [n for n in ("x", "y", "z") if n not in names]
    if missing:
        raise InputError("%s: the header line must name columns x, y, z (missing %s; found "
                         "'%s')" % (path, ", ".join(missing), header.strip()[:80]))
    duplicates = sorted(n for n, c in Counter(names).items() if c > 1)
    if duplicates or "" in names:
        raise InputError("%s: the header has %s" % (
            path, "duplicate columns " + ", ".join(duplicates) if duplicates
            else "an empty column name"))
    n_cols = len(names)
    body = body.rstrip("\n")
    if not body.strip():
        raise InputError("%s: a header but no data rows" % path)
    if "#" not in body and _every_line_has_commas(body, n_cols - 1):
        # The usual file: one split of the whole text instead of one per line; or, when every
        # field is a plain number, numpy's parser of the whole text.
        fields = body.replace("\n", ",")
        numbers = _all_numbers(fields, body.count("\n") + 1, n_cols)
        if numbers is not None:
            return names, list(numbers.T), 0
        tokens = fields.split(",")
        return names, [tokens[j::n_cols] for j in range(n_cols)], 0
    data = [line for line in body.split("\n")
            if line.strip() and not line.lstrip().startswith("#")]
    good = [line for line in data if line.count(",") == n_cols - 1]
    if not good:
        raise InputError("%s: no data row has the header's %d columns" % (path, n_cols))
    tokens = ",".join(good).split(",")
    return names, [tokens[j::n_cols] for j in range(n_cols)], len(data) - len(good)


def _all_numbers(fields, n_rows, n_cols):
    """(n_rows, n_cols) floats of comma-separated fields when numpy's text parser reads every
    one of them as a number, else None (then the fields are parsed one by one, which also
    handles blanks and text). Where both parse a field they give the same double (both round
    the decimal correctly); Python's float() also takes a few forms numpy does not (digit
    underscores, non-ASCII digits: numpy stops early, the count falls short) and numpy takes
    'nan(...)' that float() does not, hence the parenthesis test."""
    if "(" in fields:
        return None
    with warnings.catch_warnings():
        # numpy warns (later versions raise) where it stops before the end.
        warnings.simplefilter("ignore", DeprecationWarning)
        try:
            values = np.fromstring(fields, sep=",")
        except ValueError:
            return None
    if values.size != n_rows * n_cols:
        return None
    return values.reshape(n_rows, n_cols)


def _header_and_body(text):
    """The first line that is neither blank nor a comment, and the text after it."""
    pos = 0
    while pos < len(text):
        end = text.find("\n", pos)
        end = len(text) if end < 0 else end
        line = text[pos:end]
        if line.strip() and not line.lstrip().startswith("#"):
            return line, text[end + 1:]
        pos = end + 1
    return None, ""


def _every_line_has_commas(body, n_commas):
    data = np.frombuffer(body.encode("utf-8"), dtype=np.uint8)
    newlines = np.flatnonzero(data == 10)
    per_line = np.bincount(np.searchsorted(newlines, np.flatnonzero(data == 44)),
                           minlength=len(newlines) + 1)
    return bool(np.all(per_line == n_commas))


def _split_whitespace(path, text):
    """x y z [snr] rows: the column count is the most common one in the file (3 or 4); a first
    line 'x y z [snr]' is a header."""
    if "#" in text:
        text = re.sub(r"#[^\n]*", "", text)
    text = text.replace(",", " ")
    tokens = text.split()
    if not tokens:
        raise InputError("%s: the file has only comments" % path)
    token_line = _token_lines(text, len(tokens))
    n_lines = int(token_line[-1]) + 1
    per_line = np.bincount(token_line, minlength=n_lines)
    first = int(token_line[0])
    header_line = None
    if [t.lower() for t in tokens[:per_line[first]]] in (["x", "y", "z"], ["x", "y", "z", "snr"]):
        header_line = first
        per_line[first] = 0
    rows = per_line > 0
    if not rows.any():
        raise InputError("%s: a header but no data rows" % path)
    n_cols = int(np.argmax(np.bincount(per_line[rows])))
    if n_cols not in (3, 4):
        raise InputError("%s: expected 3 or 4 columns (x y z [snr]), most rows have %d"
                         % (path, n_cols))
    good_line = per_line == n_cols
    if header_line is not None:
        good_line[header_line] = False
    good_tokens = np.array(tokens, dtype=object)[good_line[token_line]].tolist()
    columns = [good_tokens[j::n_cols] for j in range(n_cols)]
    return ["x", "y", "z", "snr"][:n_cols], columns, int(rows.sum() - good_line.sum())


# The characters str.split() separates on, in ASCII; newline apart because it ends a row.
_SEPARATORS = np.zeros(256, dtype=bool)
_SEPARATORS[[9, 10, 11, 12, 13, 28, 29, 30, 31, 32]] = True


def _token_lines(text, n_tokens):
    """Line number of each token of text.split(), found on the bytes in numpy: splitting every
    line in Python would be the slowest step for a few hundred thousand rows."""
    data = np.frombuffer(text.encode("utf-8"), dtype=np.uint8)
    is_sep = _SEPARATORS[data]
    starts = np.flatnonzero(~is_sep & np.r_[True, is_sep[:-1]])
    if len(starts) != n_tokens:
        # Non-ASCII whitespace (which str.split() also splits on): count line by line.
        return np.repeat(np.arange(text.count("\n") + 1),
                         [len(line.split()) for line in text.split("\n")])
    return np.searchsorted(np.flatnonzero(data == 10), starts)


def _parse_floats(tokens, text_allowed=False):
    """Numbers of a column's field strings, blanks and non-numbers as NaN; or, when
    `text_allowed`, None as soon as a non-blank field is not a number (a text column such as
    phase = blind/planned)."""
    if isinstance(tokens, np.ndarray):   # parsed already (_all_numbers)
        return tokens
    try:
        return np.array(list(map(float, tokens)), dtype=float)
    except ValueError:
        pass
    values = np.empty(len(tokens))
    for i, token in enumerate(tokens):
        try:
            values[i] = float(token)
        except ValueError:
            if text_allowed and token.strip():
                return None
            values[i] = np.nan
    return values


def _build(path, names, columns, skipped):
    columns = dict(zip(names, columns))
    n_rows = len(columns["x"])
    required = ["x", "y", "z"] + (["snr"] if "snr" in names else [])
    parsed = {name: _parse_floats(columns[name]) for name in required}
    usable = np.ones(n_rows, dtype=bool)
    for name in required:
        infinite = np.flatnonzero(np.isinf(parsed[name]))
        if len(infinite):
            raise InputError("%s: data row %d: %s is %g, not a measurement (%d row%s with an "
                             "infinite value)" % (path, infinite[0] + 1, name,
                                                  parsed[name][infinite[0]], len(infinite),
                                                  "s" * (len(infinite) > 1)))
        usable &= np.isfinite(parsed[name])
    n_usable = int(np.count_nonzero(usable))
    skipped += n_rows - n_usable
    if n_usable < MIN_POINTS:
        raise InputError("%s: %d usable points (%d rows skipped), at least %d needed"
                         % (path, n_usable, skipped, MIN_POINTS))
    snr = None
    if "snr" in names:
        snr = parsed["snr"][usable]
        bad = (snr < SNR_RANGE[0]) | (snr > SNR_RANGE[1])
        if bad.any():
            raise InputError("%s: snr must be within %g..%g, found %g in %d rows"
                             % (path, SNR_RANGE[0], SNR_RANGE[1], snr[bad][0],
                                np.count_nonzero(bad)))
    extra = {}
    for name in names:
        if name in required:
            continue
        values = _parse_floats(columns[name], text_allowed=True)
        if values is None:
            extra[name] = np.array([t.strip() for t in columns[name]], dtype=str)[usable]
        else:
            extra[name] = values[usable]
    xyz = np.column_stack([parsed["x"], parsed["y"], parsed["z"]])[usable]
    check_magnitude(path, xyz, rows=np.flatnonzero(usable))
    return PointSet(xyz=xyz, snr=snr, columns=extra, n_rows_skipped=int(skipped), source=path)


def check_magnitude(path, xyz, rows=None):
    """InputError when a coordinate is beyond MAX_COORDINATE_MM; ``rows`` maps points to data
    rows (0-based) for the message."""
    far = np.flatnonzero(np.any(np.abs(xyz) > MAX_COORDINATE_MM, axis=1))
    if len(far):
        first = far[0]
        where = "data row %d" % (rows[first] + 1) if rows is not None else "point %d" % first
        value = xyz[first][np.argmax(np.abs(xyz[first]))]
        raise InputError("%s: %d point%s with a coordinate beyond +-%g mm (%s: %g): not a "
                         "measurement in millimetres" % (path, len(far), "s" * (len(far) > 1),
                                                         MAX_COORDINATE_MM, where, value))


def write_points_csv(path, xyz, columns=None):
    """x, y, z with 6 decimals (nanometres), then `columns` in order: float columns with 6
    decimals, integer ones as integers, text as is. A None column is left out."""
    xyz = np.asarray(xyz, dtype=float)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise InputError("%s: points must be (N, 3), got %s" % (path, xyz.shape))
    header = ["x", "y", "z"]
    text_cols = [_format_column(xyz[:, k]) for k in range(3)]
    for name, values in (columns or {}).items():
        if values is None:
            continue
        values = np.asarray(values)
        if values.shape != (len(xyz),):
            raise InputError("%s: column %s has shape %s, expected (%d,)"
                             % (path, name, values.shape, len(xyz)))
        if name.lower() in header:
            raise InputError("%s: column %s given twice" % (path, name))
        text = _format_column(values)
        if values.dtype.kind not in "fiub" and any("," in t or "\n" in t for t in text):
            raise InputError("%s: column %s has text with a comma or line break"
                             % (path, name))
        header.append(name.lower())
        text_cols.append(text)
    with open(path, "w") as fh:
        fh.write(",".join(header) + "\n")
        if len(xyz):
            fh.write("\n".join(map(",".join, zip(*text_cols))) + "\n")


def _format_column(values):
    """Field strings of a column (Python's own formatting beats numpy's char functions)."""
    if values.dtype.kind == "f":
        return ["%.6f" % v for v in values.tolist()]
    if values.dtype.kind in "iub":
        return ["%d" % v for v in values.astype(np.int64).tolist()]
    return [str(v) for v in values.tolist()]
