# kins.tcl: the parameters of xyzac-trt-kins (run by haltcl)
set kins xyzac-trt-kins   ;# for the messages below

# the rotation point of the C table, machine coordinates (mm)
setp xyzac-trt-kins.x-rot-point   0
setp xyzac-trt-kins.y-rot-point  -5
setp xyzac-trt-kins.z-rot-point -60

# the A axis beside and above the C table: from the INI
setp xyzac-trt-kins.y-offset $::KINS(Y_OFFSET)
setp xyzac-trt-kins.z-offset [lindex $::KINS(Z_OFFSET) 0]

# ISO senses for A and C
setp xyzac-trt-kins.conventional-directions 1

net :tool-offset motion.tooloffset.z => xyzac-trt-kins.tool-offset
puts "kins.tcl: xyzac-trt-kins configured"
