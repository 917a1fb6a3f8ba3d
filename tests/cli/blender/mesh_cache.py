# Run by tests/cli/mdd_blender.sh inside `blender -b`: imports a gale OBJ frame with no axis
# conversion (forward Y, up Z: gale's own frame), adds a Mesh Cache modifier reading gale's .mdd
# (frame_start: the run's first frame), and writes the evaluated vertex positions at one frame.
import bpy, sys
argv = sys.argv[sys.argv.index("--") + 1:]
obj_path, mdd_path, frame, first, out = argv[0], argv[1], int(argv[2]), int(argv[3]), argv[4]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=obj_path, forward_axis='Y', up_axis='Z')
ob = bpy.context.selected_objects[0]
m = ob.modifiers.new("gale", 'MESH_CACHE')
m.cache_format = 'MDD'
m.filepath = mdd_path
m.frame_start = first
bpy.context.scene.frame_set(frame)
ev = ob.evaluated_get(bpy.context.evaluated_depsgraph_get())
me = ev.to_mesh()
with open(out, "w") as f:
    for v in me.vertices:
        f.write("%r %r %r\n" % tuple(v.co))
print("verts", len(me.vertices), "axes", m.forward_axis, m.up_axis, "time", m.time_mode, m.play_mode)
