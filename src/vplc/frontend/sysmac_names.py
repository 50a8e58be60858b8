"""Omron Sysmac names vplc does not model: instructions (W502), motion instructions (W507/W508) and system-defined
variables (W501), each with the manual and the section where it is described — names and references only.

A name used in a program that is neither declared nor modelled by vplc is reported as a real Omron name that vplc
does not model (ST1007), not as a misspelt variable (ST1001). Names the prelude declares (prelude/*.st) are
found before this table is consulted, so an instruction that becomes modelled (the motion instructions the motion
prelude declares) needs no change here (tests/vplc/frontend/test_fe_sysmac_names.py).
"""
from __future__ import annotations

_W502_SECTIONS: dict[str, tuple[str, ...]] = {
    "Data Type Conversion Instructions": ("NumToEnum", "NumToDecString", "NumToHexString"),
    "Math Instructions": ("CheckReal",),
    "Array Data Instructions": ("ArySearch", "AryCmpEQ", "AryCmpNE", "AryCmpLT", "AryCmpLE", "AryCmpGT",
                                "AryCmpGE", "AryMax", "AryMin", "AryMean", "ArySD", "AryAdd", "ArySub",
                                "AryExchg"),
    "Control Instructions": ("PIDAT_HeatCool",),
    "System Control Instructions": ("ResetCJBError", "GetCJBError", "GetEIPError", "ResetEIPError", "GetNXBError",
                                    "GetMyTaskStatus", "Task_IsActive", "ActEventTask", "TraceSamp", "TraceTrig",
                                    "Lock", "Unlock"),
    "EtherCAT Communications Instructions": ("EC_CoESDOWrite", "EC_CoESDORead", "EC_StartMon", "EC_StopMon",
                                              "EC_SaveMon", "EC_CopyMon", "EC_DisconnectSlave",
                                              "EC_ConnectSlave"),
    "Socket Service Instructions": ("SktUDPCreate", "SktUDPSend", "SktUDPRcv", "SktSetOption"),
    "SD Memory Card Instructions": ("FileWriteVar", "FileReadVar", "FileOpen", "FileClose", "FileRead",
                                    "FileWrite", "FileRemove", "FileRename", "FileCopy", "DirCreate", "DirRemove"),
    "Serial Communications Instructions": ("SerialSend", "SerialRcv", "SendCmd", "ExecPMCR"),
    "NX Unit Instructions": ("NX_WriteObj", "NX_ReadObj", "NX_ChangeWriteMode"),
}

_W508_MOTION = ("MC_Power", "MC_Home", "MC_HomeWithParameter", "MC_Move", "MC_MoveAbsolute", "MC_MoveRelative",
                "MC_MoveVelocity", "MC_MoveFeed", "MC_MoveZeroPosition", "MC_MoveJog", "MC_Stop",
                "MC_ImmediateStop", "MC_Reset", "MC_ReadAxisError", "MC_SetPosition", "MC_SetOverride",
                "MC_ChangeAxisUse", "MC_TorqueControl", "MC_SetTorqueLimit", "MC_ZoneSwitch", "MC_TouchProbe",
                "MC_AbortTrigger", "MC_CamIn", "MC_CamOut", "MC_GearIn", "MC_GearOut", "MC_GearInPos",
                "MC_MoveLink", "MC_CombineAxes", "MC_Phasing", "MC_SyncMoveVelocity", "MC_SyncMoveAbsolute",
                "MC_DigitalCamSwitch",
                "MC_GroupEnable", "MC_GroupDisable", "MC_GroupStop", "MC_GroupReset", "MC_GroupImmediateStop",
                "MC_MoveLinear", "MC_MoveLinearAbsolute", "MC_MoveLinearRelative", "MC_MoveCircular2D",
                "MC_ReadGroupError", "MC_Write", "MC_ReadStatus")

_W501_SYSVARS = ("_EIP_EtnCommErr", "_EIP_PortErr", "_EIP_IPAdrCfgErr", "_EC_ErrSta", "_EC_PortErr",
                 "_EC_CommErrTbl", "_EC_PDSlavTbl", "_EC_MBXSlavTbl", "_MC_ErrSta", "_PLC_ErrSta", "_CJB_ErrSta",
                 "_AlarmFlag", "_RetainFail", "_MC_AX", "_MC_GRP", "_MC_COM")

# Further instructions of the same chapters with the page of W560 (NY-series Instructions Reference Manual, the
# instruction set of W502) where each is described, from a published index of W560's instruction pages. The text
# of those pages was not readable; the names and pages are what this table states.
_W560_PAGES_TEXT = (
    "TestABit 2-52, TestABitN 2-52, SetBits 2-66, ResetBits 2-66, SetABit 2-69, ResetABit 2-69, "
    "OutABit 2-71, EQascii 2-111, NEascii 2-113, LTascii 2-115, LEascii 2-115, GTascii 2-115, "
    "GEascii 2-115, Cmp 2-118, ZoneCmp 2-120, TableCmp 2-122, AryCmpEQV 2-130, AryCmpNEV 2-130, "
    "AryCmpLTV 2-132, AryCmpLEV 2-132, AryCmpGTV 2-132, AryCmpGEV 2-132, AccumulationTimer 2-148, "
    "Timer 2-152, AddOU 2-183, SubOU 2-190, MulOU 2-198, Rand 2-233, AryAddV 2-237, ArySubV 2-241, "
    "Fraction 2-249, AryToBCD 2-271, AryToBin 2-273, Round 2-338, RoundUp 2-338, AryOr 2-349, "
    "AryXor 2-349, AryXorN 2-349, Band 2-361, Zone 2-363, MoveBit 2-377, MoveDigit 2-379, TransBits 2-381, "
    "MemCopy 2-383, SetBlock 2-385, Exchange 2-387, AryExchange 2-389, Clear 2-393, AryShiftReg 2-408, "
    "AryShiftRegLR 2-410, ArySHL 2-413, ArySHR 2-413, NSHLC 2-418, NSHRC 2-418, Swap 2-427, Neg 2-429, "
    "Encoder 2-434, BitCnt 2-436, LineToColm 2-439, Gray 2-441, UTF8ToSJIS 2-446, SJISToUTF8 2-448, "
    "PWLApprox 2-450, PWLLineChk 2-456, MovingAverage 2-459, DispartReal 2-466, UniteReal 2-469, "
    "FixNumToString 2-476, StringToFixNum 2-478, DtToString 2-481, DateToString 2-483, DispartDigit 2-494, "
    "Dispart8Bit 2-498, PackWord 2-516, PackDword 2-518, StackPush 2-526, StackFIFO 2-535, "
    "StackLIFO 2-535, StackIns 2-538, StackDel 2-541, RecSearch 2-543, RecRangeSearch 2-548, "
    "RecSort 2-553, RecNum 2-559, RecMax 2-561, RecMin 2-561, StringLRC 2-568, StringCRCCCITT 2-570, "
    "StringCRC16 2-572, AryCRCCCITT 2-576, AryCRC16 2-578, GetByteLen 2-599, ToUCase 2-603, ToLCase 2-603, "
    "TrimL 2-605, TrimR 2-605, AddDelimiter 2-607, SubDelimiter 2-619, MULTIME 2-650, DIVTIME 2-652, "
    "DateToSec 2-664, TodToSec 2-666, SecToDate 2-670, SecToTod 2-672, ChkLeapYear 2-680, "
    "GetDaysOfMonth 2-681, DaysToMonth 2-684, GetWeekOfYear 2-688, DtToDateStruct 2-690, "
    "DateStructToDt 2-693, TruncTime 2-696, TruncDt 2-700, TruncTod 2-704, ScaleTrans 2-826, "
    "AC_StepProgram 2-829, GetTraceStatus 2-864, SetInfo 2-896, RestartNXUnit 2-898, NX_SaveParam 2-908, "
    "PrgStart 2-924, PrgStop 2-933, PrgStatus 2-952, IOL_ReadObj 2-1044, IOL_WriteObj 2-1053, "
    "CIPOpen 2-1065, CIPWrite 2-1085, CIPSend 2-1091, CIPClose 2-1096, CIPUCMMRead 2-1099, "
    "CIPUCMMWrite 2-1105, CIPUCMMSend 2-1112, ChangeIPAdr 2-1169, ChangeFTPAccount 2-1178, "
    "FTPGetFileList 2-1182, FTPGetFile 2-1197, FTPPutFile 2-1206, FTPRemoveFile 2-1217, "
    "FTPRemoveDir 2-1227, NX_SerialSend 2-1232, NX_SerialRcv 2-1244, NX_ModbusRtuCmd 2-1258, "
    "NX_SerialSigCtl 2-1290, NX_SerialBufClear 2-1297, NX_SerialStartMon 2-1307, NX_SerialStopMon 2-1311, "
    "FileSeek 2-1335, FileGets 2-1354, FilePuts 2-1362, ChkRange 2-1440"
)

# System-defined data types of instructions vplc does not model (the manual describing the instruction that takes
# each): declaring a variable of one is ST1007, not "unknown data type".
_SYSTEM_TYPES = {"_sTimer": "W560 2-152, Timer", "_sSDO_ACCESS": "W502, EtherCAT Communications Instructions",
                 "_sNXUNIT_ID": "W502, NX Unit Instructions", "_eMC_COORD_SYSTEM": "W508, axes group instructions",
                 "_eMC_TRANSITION_MODE": "W508, axes group instructions",
                 "_sGROUP_REF": "W507/W508, axes groups: MC_Group000, _MC_GRP[n]"}

# Values of those enumerations that published axes-group code names (an enumeration the prelude does not declare
# leaves its values undeclared too): MC_MoveLinear*'s TransitionMode and CoordSystem inputs (W508).
_SYSTEM_ENUM_VALUES = {"_mcTMNone": "_eMC_TRANSITION_MODE", "_mcTMCornerSuperimposed": "_eMC_TRANSITION_MODE",
                       "_mcACS": "_eMC_COORD_SYSTEM"}

SYSMAC_NAMES: dict[str, tuple[str, str]] = {}
for _section, _names in _W502_SECTIONS.items():
    for _n in _names:
        SYSMAC_NAMES[_n.upper()] = ("instruction", f"W502, {_section}")
for _entry in _W560_PAGES_TEXT.split(","):
    _n, _page = _entry.split()
    SYSMAC_NAMES.setdefault(_n.upper(), ("instruction", f"W560 {_page}, the same instruction as W502's"))
for _n in _W508_MOTION:
    SYSMAC_NAMES.setdefault(_n.upper(), ("motion instruction", "W508"))
for _n, _where in _SYSTEM_TYPES.items():
    SYSMAC_NAMES.setdefault(_n.upper(), ("system-defined data type", _where))
for _n, _enum in _SYSTEM_ENUM_VALUES.items():
    SYSMAC_NAMES.setdefault(_n.upper(), ("enumeration value", f"W508, {_enum}, axes group instructions"))
for _n in _W501_SYSVARS:
    SYSMAC_NAMES.setdefault(_n.upper(), ("system-defined variable", "W501, system-defined variables"))


def describe(name: str) -> str | None:
    """``Sysmac instruction `X` (W502, ...)`` for an Omron name vplc does not model, else None."""
    hit = SYSMAC_NAMES.get(name.rsplit("\\", 1)[-1].upper())
    if hit is None:
        return None
    kind, where = hit
    return f"Sysmac {kind} `{name}` ({where}) is not modelled by vplc"
