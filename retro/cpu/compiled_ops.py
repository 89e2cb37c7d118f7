"""ADC, SBC and ARR for the compiled engine's generated code (`retro.cpu.translate`): functions of ints
compiled by numba once per process, which a routine's generated code calls (one line, one call site for
numba to type) rather than repeating them: a routine's compile time grows with its lines and far faster
with its branches. (Not in numba's own disk cache: only the engine's checked entries are ever loaded;
a cached routine carries the code it calls.) And `Pipeline`, numba's compiler without its SSA pass,
whose cost grows with the square of a function's branches (measured: 30% of a 200-branch function).

Each returns (A, nv, zv, V, C): N is bit 7 of nv, Z is set when zv == 0 (the generated code's lazy
flags, `retro.cpu.translate`). Without numba they stay plain Python (the engine is then off and says
why: `retro.cpu.compiled.numba_problem`). The rules are those of the batched core (`retro.cpu.batch`,
`retro.cpu.batch65c02`) for one call: Bruce Clark, "Decimal Mode", appendix A (the NMOS 6502's A, C,
N, V and Z; the 65C02's valid N and Z), and "NMOS 6510 Unintended Opcodes - No More Secrets" for ARR.
"""

from __future__ import annotations

try:
    from llvmlite import ir as llvm_ir
    from numba import njit, types
    from numba.core.compiler import CompilerBase, DefaultPassBuilder
    from numba.core.compiler_machinery import PassManager
    from numba.extending import intrinsic
except Exception:  # noqa: BLE001 - an unsupported Python or numpy fails at import in many ways
    def njit(*args, **kwargs):
        return lambda function: function
    CompilerBase = object
    DefaultPassBuilder = None
    intrinsic = None


# numba's passes (by class name) for what generated code never holds: `with` blocks, closures and inner
# functions, functions marked for inlining, dynamic raises, `literally` and `literal_unroll`, parfors,
# and the rewrites after typing (array expressions, string literals). Each pass that changes the IR
# has numba recompute variable lifetimes over every block, which grows with blocks times variables:
# without them aabb_sprite's compile makes 21% fewer Python calls (8.5 M against 10.7 M, cProfile).
UNUSED_PASSES = frozenset({"WithLifting", "InlineClosureLikes", "RewriteDynamicRaises", "MakeFunctionToJitFunction",
                           "InlineInlinables", "FindLiterallyCalls", "LiteralUnroll", "NopythonRewrites",
                           "DumpParforDiagnostics"})


class Pipeline(CompilerBase):
    """numba's nopython pipeline without SSA reconstruction (the generated functions assign every
    variable an int64: their types need no SSA to unify, and the pass is quadratic in their branches)
    and without UNUSED_PASSES (a name this numba does not have is simply not there to leave out)."""

    def define_pipelines(self):
        self.state.flags.enable_ssa = False
        default = DefaultPassBuilder.define_nopython_pipeline(self.state)
        pipeline = PassManager(default.pipeline_name)
        for kind, description in default.passes:
            if kind.__name__ not in UNUSED_PASSES:
                pipeline.add_pass(kind, description)
        pipeline.finalize()
        return [pipeline]


def _jit(function):
    return njit(function)


@_jit
def adc_binary(a, value, carry):
    """ADC without decimal mode (and SBC, given the operand's complement)."""
    total = a + value + carry
    result = total & 0xFF
    return result, result, result, (((a ^ total) & (value ^ total)) >> 7) & 1, total >> 8


@_jit
def adc_decimal_nmos(a, value, carry):
    """NMOS ADC with D set: Clark's sequences 1 and 2; Z from the binary sum."""
    total = a + value + carry
    low = (a & 0x0F) + (value & 0x0F) + carry
    if low >= 0x0A:
        low = ((low + 0x06) & 0x0F) + 0x10
    high = (a & 0xF0) + (value & 0xF0) + low
    signed = (a & 0xF0) - ((a & 0x80) << 1) + (value & 0xF0) - ((value & 0x80) << 1) + low  # N and V before the high adjust
    overflow = 1 if (signed < -128 or signed > 127) else 0
    if high >= 0xA0:
        high += 0x60
    return high & 0xFF, signed & 0x80, total & 0xFF, overflow, 1 if high > 0xFF else 0


@_jit
def sbc_decimal_nmos(a, value, carry):
    """NMOS SBC with D set: flags from the binary difference, A by Clark's sequence 3."""
    binary = a + (value ^ 0xFF) + carry
    result = binary & 0xFF
    overflow = ((a ^ binary) & ((value ^ 0xFF) ^ binary) & 0x80) >> 7
    low = (a & 0x0F) - (value & 0x0F) - (1 - carry)
    if low < 0:
        low = ((low - 0x06) & 0x0F) - 0x10
    high = (a & 0xF0) - (value & 0xF0) + low
    if high < 0:
        high -= 0x60
    return high & 0xFF, result, result, overflow, binary >> 8


@_jit
def adc_decimal_cmos(a, value, carry):
    """65C02 ADC with D set: A and C by Clark's sequence 1, V by sequence 2, N and Z from A."""
    low = (a & 0x0F) + (value & 0x0F) + carry
    if low >= 0x0A:
        low = ((low + 0x06) & 0x0F) + 0x10
    total = (a & 0xF0) + (value & 0xF0) + low
    signed = (a & 0xF0) - ((a & 0x80) << 1) + (value & 0xF0) - ((value & 0x80) << 1) + low
    overflow = 1 if (signed < -128 or signed > 127) else 0
    if total >= 0xA0:
        total += 0x60
    result = total & 0xFF
    return result, result, result, overflow, 1 if total > 0xFF else 0


@_jit
def sbc_decimal_cmos(a, value, carry):
    """65C02 SBC with D set: C and V from the binary difference, A by Clark's sequence 4, N and Z from A."""
    binary = a + (value ^ 0xFF) + carry
    overflow = ((a ^ binary) & ((value ^ 0xFF) ^ binary) & 0x80) >> 7
    borrow = 1 - carry
    low = (a & 0x0F) - (value & 0x0F) - borrow
    total = a - value - borrow
    if total < 0:
        total -= 0x60
    if low < 0:
        total -= 0x06
    result = total & 0xFF
    return result, result, result, overflow, binary >> 8


@_jit
def arr(value, carry, decimal):
    """ARR on A AND the operand (`value`): ROR with its own flags; in decimal mode (NMOS) as 64doc."""
    result = (value >> 1) | (carry << 7)
    if not decimal:
        return result, result, result, ((result >> 6) ^ (result >> 5)) & 1, (result >> 6) & 1
    low = value & 0x0F
    high = value >> 4
    overflow = 1 if (value ^ result) & 0x40 else 0
    adjusted = result
    if low + (low & 1) > 5:
        adjusted = (result & 0xF0) | ((result + 6) & 0x0F)
    high_carry = 1 if high + (high & 1) > 5 else 0
    if high_carry:
        adjusted = (adjusted + 0x60) & 0xFF
    return adjusted, carry << 7, result, overflow, high_carry


@_jit
def adc_nmos(a, value, carry, decimal):
    return adc_decimal_nmos(a, value, carry) if decimal else adc_binary(a, value, carry)


@_jit
def sbc_nmos(a, value, carry, decimal):
    return sbc_decimal_nmos(a, value, carry) if decimal else adc_binary(a, value ^ 0xFF, carry)


@_jit
def adc_cmos(a, value, carry, decimal):
    """(The 65C02 takes a cycle more in decimal mode: the caller adds D to the cycles.)"""
    return adc_decimal_cmos(a, value, carry) if decimal else adc_binary(a, value, carry)


@_jit
def sbc_cmos(a, value, carry, decimal):
    return sbc_decimal_cmos(a, value, carry) if decimal else adc_binary(a, value ^ 0xFF, carry)


if intrinsic is not None:
    @intrinsic
    def _select(typingctx, condition, taken, other):
        """LLVM's `select` of two values each passed through an empty inline assembly block (no
        instruction): with a value it can still see as a load, LLVM's code generator turns the select
        back into a jump (to load only on the way that needs it), mispredicted half the time on
        random data: the very cost the selection is there to remove."""
        def codegen(context, builder, signature, args):
            word = llvm_ir.IntType(64)
            opaque = llvm_ir.FunctionType(word, [word])
            taken_value, other_value = (builder.asm(opaque, "", "=r,0", [value], side_effect=False)
                                        for value in args[1:])
            flag = builder.icmp_signed("!=", args[0], llvm_ir.Constant(word, 0))
            return builder.select(flag, taken_value, other_value)
        return types.int64(types.int64, types.int64, types.int64), codegen
else:
    def _select(condition, taken, other):
        return taken if condition else other


@_jit
def choose(condition, taken, other):
    """`taken` when `condition` is not 0, else `other`, without a jump (a conditional move): the
    compiled engine's if-converted branches (retro.cpu.translate) keep one way's state by it."""
    return _select(condition, taken, other)


HELPERS = ("adc_binary", "adc_nmos", "sbc_nmos", "adc_cmos", "sbc_cmos", "arr", "choose",
           "Pipeline")  # what generated code uses
