from setuptools import find_packages, setup

package_name = 'multilift_learning'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='multilift developers',
    maintainer_email='dev@multilift.dev',
    description='Gymnasium environments of multilift on the batched engine.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'policy_node = multilift_learning.ros.policy_node:main',
        ],
    },
)
