// node validate_gltf.mjs VALIDATOR_PACKAGE_DIR SCENE.gltf
// Runs the Khronos glTF validator on SCENE.gltf and the files it references, prints the issue
// counts and every message, and exits 0 only when there are no errors.
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';
import path from 'node:path';

const [packageDir, scene] = process.argv.slice(2);
if (!packageDir || !scene) {
    console.error('usage: node validate_gltf.mjs VALIDATOR_PACKAGE_DIR SCENE.gltf');
    process.exit(2);
}
const validator = createRequire(import.meta.url)(path.resolve(packageDir));
const sceneDir = path.dirname(path.resolve(scene));
const severities = ['error', 'warning', 'info', 'hint'];

try {
    const report = await validator.validateBytes(new Uint8Array(await readFile(scene)), {
        uri: path.basename(scene),
        format: 'gltf',
        maxIssues: 0,
        writeTimestamp: false,
        externalResourceFunction: async (uri) =>
            new Uint8Array(await readFile(path.resolve(sceneDir, decodeURIComponent(uri)))),
    });
    const issues = report.issues;
    console.log(`${scene}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
                `${issues.numInfos} infos, ${issues.numHints} hints ` +
                `(gltf-validator ${report.validatorVersion})`);
    for (const m of issues.messages) {
        console.log(`  ${severities[m.severity] ?? m.severity} ${m.code}` +
                    `${m.pointer ? ' at ' + m.pointer : ''}: ${m.message}`);
    }
    const resources = (report.info?.resources ?? []).map((r) => r.uri).filter(Boolean);
    if (resources.length > 0)
        console.log(`  resources: ${resources.join(', ')}`);
    process.exit(issues.numErrors === 0 ? 0 : 1);
} catch (e) {
    console.error(`${scene}: the validator could not run: ${e}`);
    process.exit(1);
}
