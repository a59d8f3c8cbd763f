#!/usr/bin/python3
"""Pack a build for a GPU machine that cannot build or install (no network, another distro).

usage: python3 scripts/gpu_bundle.py [--build DIR] [--out DIR] [--archive]

Copies the tool, the test binary, the OpenImageIO module libmcdenoise_oiio.so (beside the tool,
where both look for it) and the built SPIR-V (the test binary reads some of it from
<build>/shaders) into OUT/build/, and into OUT/lib/ every shared library they load except the
C and C++ runtimes, plus the Vulkan loader (mcdenoise opens it at run time) and libglvnd's
dispatch libraries (NVIDIA's Vulkan driver lives in its GLX library and needs them), and the
Khronos validation layer with its manifest in OUT/layers (the tests run with it on). OpenImageIO
links image formats mcdenoise never reads or writes (video, DICOM, VDB, HEIF, JPEG 2000,
camera raw, GIF, fonts, colour management); those libraries and everything below them are
replaced by empty stand-ins: each defines the symbols and symbol versions its users import,
as functions that return a pointer to zeroed memory, so the loader is satisfied and nothing
of them runs (`gpu_bench.sh --bundle` keeps OpenImageIO from trying them on a file its
extension's reader cannot open). Then `scripts/gpu_bench.sh --bundle OUT` runs there (see
docs/performance.md). --archive also writes OUT.tar.xz (a fifth of the size, for a machine
that takes a limited upload), which `gpu_bench.sh --bundle OUT.tar.xz` unpacks.
"""
import argparse, os, re, shutil, subprocess, sys, tarfile, tempfile

LIBDIRS = ['/lib/x86_64-linux-gnu', '/usr/lib/x86_64-linux-gnu']
# Runtimes every target machine has, newer than ours.
SYSTEM = {'libc.so.6', 'libm.so.6', 'ld-linux-x86-64.so.2', 'libgcc_s.so.1', 'libstdc++.so.6',
          'libpthread.so.0', 'libdl.so.2', 'librt.so.1'}
# Loaded at run time: the Vulkan loader, and the libglvnd libraries NVIDIA's driver needs.
RUNTIME = ['libvulkan.so.1', 'libGLdispatch.so.0', 'libGLX.so.0', 'libOpenGL.so.0', 'libGL.so.1',
           'libEGL.so.1', 'libGLESv2.so.2']
# The validation layer's manifest (its library_path is a bare soname) and library.
VALIDATION = ['/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json',
              'libVkLayer_khronos_validation.so']
# OpenImageIO's format libraries that mcdenoise never calls (prefixes of their sonames).
STANDINS = ('libopencv', 'libdcm', 'liboflog', 'libofstd', 'libavcodec', 'libavformat',
            'libavutil', 'libswscale', 'libheif', 'libopenjp2', 'libopenvdb', 'libraw_r',
            'libOpenColorIO', 'libfreetype', 'libgif')


def Run(args):
    return subprocess.run(args, capture_output=True, text=True, check=True).stdout


def Needed(path):
    return re.findall(r'\(NEEDED\).*\[(.*)\]', Run(['readelf', '-d', path]))


def Find(soname):
    for d in LIBDIRS:
        if os.path.exists(os.path.join(d, soname)):
            return os.path.join(d, soname)
    sys.exit(f'gpu_bundle: {soname} not found in {LIBDIRS}')


def Closure(binaries):
    """Return (real libraries to copy, libraries to stand in for), by soname."""
    real, standins, todo = {}, {}, list(binaries)
    while todo:
        for soname in Needed(todo.pop()):
            if soname in SYSTEM or soname in real or soname in standins:
                continue
            if soname.startswith(STANDINS):
                standins[soname] = Find(soname)
            else:
                real[soname] = Find(soname)
                todo.append(real[soname])
    return real, standins


def Imports(paths):
    """Names of the dynamic symbols the given objects import."""
    names = set()
    for path in paths:
        for line in Run(['objdump', '-T', path]).splitlines():
            if '*UND*' in line:
                names.add(line.split()[-1])
    return names


def WriteStandin(original, imports, outDir, tmp):
    """Build an empty library with the soname, imported symbols and versions of original."""
    soname = os.path.basename(original)
    asm = ['.data', 'zeros: .zero 256', '.text']
    versions, unversioned = {}, []
    pattern = re.compile(r'^[0-9a-f]+ (.{7}) (\S+)\s+([0-9a-f]+)\s+(\S+)\s+(\S+)$')
    for line in Run(['objdump', '-T', original]).splitlines():
        m = pattern.match(line.rstrip())
        if not m or m.group(2) == '*UND*' or m.group(5) not in imports:
            continue
        flags, size, version, name = m.group(1), int(m.group(3), 16), m.group(4), m.group(5)
        if 'O' in flags:  # data: zeroed storage of the original's size
            asm += ['.data', f'.globl "{name}"', f'.type "{name}",@object',
                    f'.size "{name}",{max(size, 1)}', f'"{name}":', f'.zero {max(size, 8)}',
                    '.text']
        else:
            asm += [f'.globl "{name}"', f'.type "{name}",@function', f'"{name}":',
                    'lea zeros(%rip), %rax', 'ret']
        version = version.strip('()')
        (versions.setdefault(version, []) if version != 'Base' else unversioned).append(name)
    # Every version the original defines, so the loader's version checks pass.
    defined = Run(['readelf', '-V', original]).split('.gnu.version_r')[0]
    for version in re.findall(r'Name: (\S+)', defined):
        if version != soname:
            versions.setdefault(version, [])
    source = os.path.join(tmp, 'standin.s')
    with open(source, 'w') as f:
        f.write('\n'.join(asm) + '\n')
    command = ['gcc', '-shared', '-nostdlib', '-o', os.path.join(outDir, soname), source,
               '-Wl,-soname,' + soname]
    if versions:
        first = next(iter(versions))
        versions[first] += unversioned
        script = os.path.join(tmp, 'standin.map')
        with open(script, 'w') as f:
            for version, names in versions.items():
                f.write(f'{version} {{ global: {"".join(f"{chr(34)}{n}{chr(34)};" for n in names)} }};\n')
        command.append('-Wl,--version-script=' + script)
    Run(command)


def Main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--build', default='build')
    parser.add_argument('--out', default='gpu_bundle')
    parser.add_argument('--archive', action='store_true', help='also write OUT.tar.xz')
    args = parser.parse_args()
    # The OpenImageIO module sits beside the tool, where the tool and the tests look for it.
    places = ['mcdenoise', 'tests/mcd_tests', 'libmcdenoise_oiio.so']
    binaries = [os.path.join(args.build, p) for p in places]
    for b in binaries:
        if not os.path.isfile(b):
            sys.exit(f'gpu_bundle: {b} not found (build first)')
    shutil.rmtree(args.out, ignore_errors=True)
    lib = os.path.join(args.out, 'lib')
    os.makedirs(os.path.join(args.out, 'build', 'tests'))
    os.makedirs(lib)
    for b, place in zip(binaries, places):
        Run(['strip', '--strip-unneeded', '-o', os.path.join(args.out, 'build', place), b])
    shutil.copytree(os.path.join(args.build, 'shaders'), os.path.join(args.out, 'build', 'shaders'),
                    ignore=lambda d, names: [n for n in names
                                             if not n.endswith('.spv') and
                                             not os.path.isdir(os.path.join(d, n))])
    real, standins = Closure(binaries)
    for soname, path in real.items():
        shutil.copyfile(os.path.realpath(path), os.path.join(lib, soname))
    for soname in RUNTIME:
        shutil.copyfile(os.path.realpath(Find(soname)), os.path.join(lib, soname))
    layers = os.path.join(args.out, 'layers')
    os.makedirs(layers)
    shutil.copyfile(VALIDATION[0], os.path.join(layers, os.path.basename(VALIDATION[0])))
    shutil.copyfile(os.path.realpath(Find(VALIDATION[1])), os.path.join(lib, VALIDATION[1]))
    imports = Imports(binaries + [os.path.join(lib, s) for s in real])
    with tempfile.TemporaryDirectory() as tmp:
        for path in standins.values():
            WriteStandin(path, imports, lib, tmp)
    size = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(args.out) for f in fs)
    print(f'gpu_bundle: {args.out}: {len(real) + len(RUNTIME)} libraries, {len(standins)} stand-ins, '
          f'{size / 2**20:.1f} MiB')
    if args.archive:
        archive = args.out.rstrip('/') + '.tar.xz'
        with tarfile.open(archive, 'w:xz') as tar:
            tar.add(args.out, arcname=os.path.basename(args.out.rstrip('/')))
        print(f'gpu_bundle: {archive}: {os.path.getsize(archive) / 2**20:.1f} MiB')


if __name__ == '__main__':
    Main()
