"""The parsed form of an LCM type (Struct, Member, Enum) and the facts about
LCM's primitive types that the other steps share."""

DEFAULT_MAX_COUNT = 65536
DEFAULT_MAX_STRING = 4096
GLOBAL_MAX_SIZE = 16 * 1024 * 1024   # no message of ours may exceed this

PRIM_SIZE = {"int8_t": 1, "int16_t": 2, "int32_t": 4, "int64_t": 8, "byte": 1,
             "float": 4, "double": 8, "boolean": 1}
PRIMITIVES = set(PRIM_SIZE) | {"string"}
DIM_TYPES = {"int8_t", "int16_t", "int32_t", "int64_t"}
INT_TYPES = DIM_TYPES | {"byte"}
REAL_TYPES = {"float", "double"}
INT_RANGE = {"int8_t": (-(1 << 7), (1 << 7) - 1), "int16_t": (-(1 << 15), (1 << 15) - 1),
             "int32_t": (-(1 << 31), (1 << 31) - 1), "int64_t": (-(1 << 63), (1 << 63) - 1),
             "byte": (0, 255)}


class GenError(Exception):
    pass


def camel(name):
    """The C++ spelling the generated names share: CAGE_POS_Y, cage_pos_y ->
    CagePosY (enumerators, enum and table stems, group structs, channels)."""
    return "".join(w.capitalize() for w in name.strip("_").split("_"))


class Member:
    def __init__(self, type_, name, dims, line, desc):
        self.type = type_
        self.name = name
        self.dims = dims          # list of (mode, size) with mode 0 = const, 1 = var
        self.line = line
        self.desc = desc
        self.max_count = None     # for var arrays
        self.max_len = DEFAULT_MAX_STRING
        self.struct = None        # the Struct of a nested (non-primitive) member
        self.enum = None          # the Enum naming this member's values (@enum)
        self.csv_name = name      # CSV column (stem, for an array) (@csv)
        self.csv_first = 0        # index of an array's first CSV column (@csv)
        self.group = None         # the writer's group of a counter (@group)

    @property
    def nested(self):
        return self.type not in PRIMITIVES

    @property
    def var_array(self):
        return bool(self.dims) and self.dims[0][0] == 1


class Enum:
    """The consts PREFIX_<NAME> of a struct that name the values of one of its
    members (`// @enum MEMBER PREFIX_`): names[i] is the value first + i."""

    def __init__(self, member, prefix, first, names, ctype="int64_t"):
        self.member = member      # member name
        self.ctype = ctype        # the consts' C integer type (the widest of them)
        self.prefix = prefix      # "LEVEL_"
        self.first = first        # value of names[0]
        self.names = names        # ["NONE", "WARNING", "CRITICAL"]

    @property
    def camel(self):
        """The enumerators of enum class <Stem>: CAGE_POS_Y -> CagePosY."""
        return [camel(n) for n in self.names]

    @property
    def stem(self):
        """LEVEL_ -> Level, EVENT_ -> Event, RUN_MODE_ -> RunMode."""
        return camel(self.prefix)


class Struct:
    def __init__(self, package, name, desc, path):
        self.package = package
        self.name = name
        self.desc = desc
        self.path = path
        self.members = []
        self.consts = []          # (type, name, value text)
        self.max_annot = {}       # count member -> N
        self.maxlen_annot = {}    # string member -> N
        self.enum_annot = {}      # member -> const prefix
        self.csv_annot = {}       # member -> (column name, first index)
        self.csv_first = []       # members whose CSV columns come first, in order
        self.enums = []           # Enum, in the order of the annotations
        self.channel = None       # its LCM channel without the prefix (@channel)

    @property
    def full(self):
        return f"{self.package}.{self.name}" if self.package else self.name
